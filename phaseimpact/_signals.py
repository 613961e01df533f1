"""Ctrl-C (SIGINT) and SIGTERM during compiled runs: they stop within a second, never crash.

Two problems, one mechanism:

* Compiled code holds the GIL (or runs without it in worker threads) and never runs Python's
  signal handlers, so a long run went on to its end. Python's C-level handler also writes the
  signal's number to the "wakeup fd" (:func:`signal.set_wakeup_fd`): that is a pipe of ours, and
  the driver polls its read end every few thousand steps (:func:`interrupted`, a ``poll`` system
  call reached through a symbol registered with LLVM, so the machine code stays cacheable) and
  returns with the status ``interrupted``.
* When a compiled function returns arrays, numba's wrapper calls back into Python to build them
  (``numba.core.serialize._numba_unpickle``) and does not check that call for an exception. A
  pending Ctrl-C ran its handler there: the ``KeyboardInterrupt`` became a ``SystemError``
  ("CPUDispatcher(run) returned a result with an exception set") or a NULL type pointer and a
  segfault. :func:`handler` therefore only records a signal that arrives inside that callback
  (:data:`deferred`); the caller of the compiled run raises it with :func:`check` once the result
  is back. The same for a signal that arrives while Python runs a weak-reference callback or a
  ``__del__`` (an object freed, often inside h5py or NumPy): Python prints "Exception ignored" there
  and drops the ``KeyboardInterrupt``, and an atlas ran on to its end and exited 0.

A signal's byte is left in the pipe when it is acted on, so that every thread running compiled
code sees it and stops; a later run that is woken by such an old byte (nothing :data:`deferred`)
clears the pipe and runs again (:func:`check`). A worker thread whose work belongs to the stopped
caller (a Dask task of an in-process cluster: :func:`stopping_with_the_caller`) must not run again:
it would hold the cluster's shutdown for a whole chunk. Each signal acted on is therefore counted,
and such a thread raises it instead when a signal was acted on since its work began.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import threading
import weakref

import llvmlite.binding as llvm
from llvmlite import ir
from numba import types
from numba.core import cgutils, config
from numba.extending import intrinsic

__all__ = ["Terminated", "install", "install_command_line", "interrupted", "check", "exit_code", "deferred",
           "stopping_with_the_caller"]


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that the same clean-up runs (locks, temporary files, the
    resume hint); the command line exits with 143 for it."""


#: Signals that arrived while numba built a compiled function's result; raised by :func:`check`.
deferred: list[int] = []

# The read end of the wakeup pipe, read by compiled code through the symbol below (-1: none).
_FD = ctypes.c_int(-1)
_WRITE_FD = -1
_FD_SYMBOL = "phaseimpact_interrupt_fd"
_POLL_SYMBOL = "phaseimpact_poll"
_POLLIN = 1
llvm.add_symbol(_FD_SYMBOL, ctypes.addressof(_FD))
llvm.add_symbol(_POLL_SYMBOL, ctypes.cast(ctypes.CDLL(None).poll, ctypes.c_void_p).value)


@intrinsic
def interrupted(typingctx):
    """Compiled code only: has a signal arrived (does the wakeup pipe hold a byte)?
    ``poll({fd, POLLIN}, 1, 0)``, about 0.3 us, skipped without a pipe. Only symbols are referenced,
    no addresses, so numba's disk cache stays valid. On a GPU (numba's CUDA target) always False:
    the device has no system calls, and a signal stops the host between kernel launches instead."""
    def codegen(context, builder, sig, args):
        i16, i32, i64 = ir.IntType(16), ir.IntType(32), ir.IntType(64)
        module = builder.module
        if module.triple.startswith("nvptx"):
            return ir.Constant(ir.IntType(1), 0)
        fd_var = module.globals.get(_FD_SYMBOL)
        if fd_var is None:
            fd_var = ir.GlobalVariable(module, i32, _FD_SYMBOL)
            fd_var.linkage = "external"
        pollfd = ir.LiteralStructType([i32, i16, i16])  # struct pollfd {int fd; short events, revents;}
        poll = cgutils.get_or_insert_function(module, ir.FunctionType(i32, [pollfd.as_pointer(), i64, i32]),
                                              _POLL_SYMBOL)
        entry = cgutils.alloca_once(builder, pollfd)
        woken = cgutils.alloca_once_value(builder, ir.Constant(ir.IntType(1), 0))
        fd = builder.load(fd_var)
        with builder.if_then(builder.icmp_signed(">=", fd, i32(0)), likely=False):
            builder.store(ir.Constant(pollfd, [0, _POLLIN, 0]), entry)
            builder.store(fd, builder.gep(entry, [i32(0), i32(0)], inbounds=True))
            ready = builder.call(poll, [entry, i64(1), i32(0)])
            revents = builder.load(builder.gep(entry, [i32(0), i32(2)], inbounds=True))
            readable = builder.icmp_unsigned("!=", builder.and_(revents, i16(_POLLIN)), i16(0))
            builder.store(builder.and_(builder.icmp_signed(">", ready, i32(0)), readable), woken)
        return builder.load(woken)
    return types.boolean(), codegen


if config.DISABLE_JIT:
    def interrupted():  # noqa: F811  uncompiled (NUMBA_DISABLE_JIT=1): Python's handler raises inside the run
        return False


def _in_ignoring_context(frame) -> bool:
    """Is ``frame`` inside code whose exceptions Python or numba drop: numba's callback that builds a
    compiled function's result, a weak-reference callback or a finaliser (``__del__``)?"""
    from numba.core import serialize

    code = serialize._numba_unpickle.__code__
    while frame is not None:
        f_code = frame.f_code
        if f_code is code or f_code.co_name == "__del__" or f_code.co_filename == weakref.__file__:
            return True
        frame = frame.f_back
    return False


#: Signals acted on (raised) in this process, and the last of them: see stopping_with_the_caller.
_acted = [0, signal.SIGINT]
_thread = threading.local()


def _raise(signum: int):
    if signum == signal.SIGTERM:
        raise Terminated()
    raise KeyboardInterrupt()


def _act(signum: int):
    """Raise ``signum`` in this thread, counted; a byte goes back into the pipe so that a worker
    thread that cleared it before this count (an old byte, it thought) is woken again."""
    _acted[:] = [_acted[0] + 1, signum]
    if _WRITE_FD >= 0:
        try:
            os.write(_WRITE_FD, b"\0")
        except OSError:  # a full pipe holds bytes enough
            pass
    _raise(signum)


@contextlib.contextmanager
def stopping_with_the_caller():
    """In a worker thread: a signal acted on while the block runs raises it here too (from
    :func:`check`), instead of the run being repeated as after an old byte."""
    _thread.since = _acted[0]
    try:
        yield
    finally:
        del _thread.since


def handler(signum, frame):
    """SIGINT/SIGTERM: raise ``KeyboardInterrupt`` (:class:`Terminated`), or record the signal when
    it arrives where an exception is lost or crashes (:func:`_in_ignoring_context`)."""
    if _in_ignoring_context(frame):
        deferred.append(signum)
        return
    _act(signum)


def _open_pipe() -> bool:
    """Make a pipe of ours the wakeup fd, unless another one is set (an event loop's)."""
    global _WRITE_FD
    if _FD.value >= 0:
        return True
    read, write = os.pipe2(os.O_NONBLOCK | os.O_CLOEXEC)
    try:
        old = signal.set_wakeup_fd(write, warn_on_full_buffer=False)
    except ValueError:  # not the main thread
        old = None
    if old != -1:
        if old is not None:
            signal.set_wakeup_fd(old)
        os.close(read)
        os.close(write)
        return False
    _FD.value, _WRITE_FD = read, write
    return True


def _after_fork_in_child() -> None:
    # a forked child must not write its signals into its parent's pipe, nor read the parent's
    global _WRITE_FD
    if _FD.value >= 0:
        try:
            signal.set_wakeup_fd(-1)
        except ValueError:
            pass
        for fd in (_FD.value, _WRITE_FD):
            try:
                os.close(fd)
            except OSError:
                pass
        _FD.value, _WRITE_FD = -1, -1
    deferred.clear()


os.register_at_fork(after_in_child=_after_fork_in_child)

#: Whether install() or install_command_line() has run (the library calls install() before a first run).
installed = False


def install() -> None:
    """For the library (called before its first compiled run): take over Ctrl-C if it still has
    Python's default handler, in the main thread only; anything else is left as it is."""
    global installed
    if installed or threading.current_thread() is not threading.main_thread():
        return
    installed = True
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        _open_pipe()
        signal.signal(signal.SIGINT, handler)


def install_command_line() -> None:
    """For the command line: Ctrl-C and SIGTERM both end the command cleanly (where they are not
    ignored, as ``nohup`` or a shell's background job asks)."""
    global installed
    if threading.current_thread() is not threading.main_thread():
        return
    installed = True
    _open_pipe()
    if signal.getsignal(signal.SIGINT) in (signal.default_int_handler, handler):
        signal.signal(signal.SIGINT, handler)
    if signal.getsignal(signal.SIGTERM) in (signal.SIG_DFL, handler):
        signal.signal(signal.SIGTERM, handler)


def _drain() -> None:
    while True:
        try:
            if not os.read(_FD.value, 4096):
                return
        except (BlockingIOError, OSError):
            return


def check(woken: bool) -> None:
    """After a compiled run: raise the signal that arrived during it (deferred, see
    :func:`handler`). ``woken``: the run stopped because the pipe held a byte; if nothing is
    deferred, that byte is an old one (a signal already acted on): the pipe is cleared and the
    caller runs again, unless a signal was acted on since a :func:`stopping_with_the_caller` block
    of this thread began: it is raised here too."""
    if deferred:
        signum = signal.SIGTERM if signal.SIGTERM in deferred else deferred[0]
        deferred.clear()
        _act(signum)
    since = getattr(_thread, "since", None)
    if woken and since is not None and _acted[0] != since:
        _raise(_acted[1])
    if woken and _FD.value >= 0:
        _drain()


def exit_code(stop: KeyboardInterrupt) -> int:
    """The command line's exit code: 143 for SIGTERM, 130 for Ctrl-C (128 + the signal's number)."""
    return 128 + (signal.SIGTERM if isinstance(stop, Terminated) else signal.SIGINT)

"""The GPU kernel's compile, without a GPU: its PTX for an H100 (sm_90) with the engine's calls kept
(``phaseimpact.cuda``'s call policy, the default) and with numba's own inlining
(``PHASEIMPACT_GPU_CALLS=0``), side by side: the compile's seconds (numba's typing and lowering,
then NVVM), NVVM's part, and the PTX's size and functions. The policy changes what is a call, not
the arithmetic (up to NVVM's fused multiply-adds across an inlined call); what the calls cost when
the kernel runs needs a GPU (``benchmarks/gpu.py``).

Each variant runs in a fresh process (tests/test_cuda.py's PTX script, the one the PTX test runs).
Needs NVVM (the CUDA toolkit's compiler library); without it, the section says so.

    python benchmarks/gpu_compile.py [--section gpu_compile]   # about 6 minutes on 2 cores (numba's
                                                               # own inlining: 5 of them)

Run it from an environment with numba-cuda too (numba's CUDA target as NVIDIA ships it apart, which
a GPU machine may have) with ``--section gpu_compile_numba_cuda``; the section names the target.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "tests"))
from _common import emit, load, machine, save_section, save_targets, table, target  # noqa: E402

VARIANTS = (("the engine's calls kept (default)", "1"), ("numba's own inlining (PHASEIMPACT_GPU_CALLS=0)", "0"))


def compile_ptx(calls: str) -> list[str]:
    """(PTX bytes, .entry, .target sm_90, polls, PTX functions, PTX lines, NVVM s, compile s, IR modules, distinct
    modules, IR characters) of one fresh process."""
    from test_cuda import PTX

    env = dict(os.environ, PYTHONPATH=str(ROOT), PHASEIMPACT_GPU_CALLS=calls)
    out = subprocess.run([sys.executable, "-c", PTX], capture_output=True, text=True, timeout=1500, cwd=ROOT, env=env)
    if out.returncode != 0:
        raise RuntimeError(out.stderr[-3000:])
    return out.stdout.split()


def cuda_target() -> str:
    """Which CUDA target numba has here: numba-cuda's (and its version) or numba's own."""
    import importlib.metadata

    try:
        return f"numba-cuda {importlib.metadata.version('numba-cuda')}"
    except importlib.metadata.PackageNotFoundError:
        return "numba's own numba.cuda"


def main(argv=None) -> int:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--section", default="gpu_compile", help="results/<section>.md and .json (default gpu_compile)")
    section = ap.parse_args(argv).section
    from numba.cuda.cudadrv import nvvm

    if not nvvm.is_available():
        text = f"## {section}\n\n{machine()}\n\nNot run: no NVVM (the CUDA toolkit's compiler library) here.\n"
        save_section(section, text)
        print(text)
        return 0
    start_load = load()
    rows, seconds = [], {}
    for name, calls in VARIANTS:
        size, _, _, _, functions, lines, nvvm_s, total, modules, distinct, ir_chars = compile_ptx(calls)
        seconds[calls] = float(total)
        rows.append((name, f"{float(total):.1f}", nvvm_s, f"{int(lines):,}", f"{int(size) / 1e6:.1f}", functions,
                     f"{modules} ({distinct} distinct), {int(ir_chars) / 1e6:.1f} MB"))
        emit(f"{name}: compile {total} s (NVVM {nvvm_s} s), PTX {int(lines):,} lines, {functions} functions")
    header = ("kernel", "compile to PTX [s]", "of which NVVM [s]", "PTX lines", "PTX MB", "PTX functions",
              "IR modules numba hands NVVM")
    command = "python benchmarks/gpu_compile.py" + ("" if section == "gpu_compile" else f" --section {section}")
    nvvm_version = ".".join(map(str, nvvm.NVVM().get_version()))
    text = (f"## {section}\n\n{machine()}; CUDA target: {cuda_target()}, NVVM {nvvm_version}\n\n"
            f"{start_load} at the start, {load()} at the end. `{command}`\n\n"
            "The GPU kernel (phaseimpact.cuda) compiled to PTX for sm_90 by numba's CUDA target, without a GPU, in a "
            "fresh process each (tests/test_cuda.py's PTX script): numba's typing and lowering, then NVVM (given "
            "each module once with the calls kept; as numba hands them otherwise). On a GPU the driver then "
            "assembles the PTX (not timed here). A single measurement each.\n\n"
            + table(header, rows))
    save_section(section, text)
    save_targets(section, [target(
        f"the GPU kernel's compile to PTX (sm_90), the engine's calls kept ({cuda_target()})",
        "shorter than numba's own inlining", f"{seconds['1']:.0f} s against {seconds['0']:.0f} s",
        bool(seconds["1"] < seconds["0"]), command)])
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env bash
# One lease of a GPU machine (16 cores, one H100 or H200), prepared to end within about 9 minutes:
# the CUDA backend against the CPU threads (gpu.py), and the parallel scaling on cores nothing else
# shares (scale.py --section scale_gpu_machine). Run from the repository root there, with that
# machine's own python3 (numpy, scipy, numba, numba-cuda, h5py, joblib and tqdm are installed
# there); the package runs from the tree (PYTHONPATH) and compiles on first use.
#
# The CUDA kernel's compile (one core; it had not finished after 559 s in the first lease, before
# the engine's calls were kept as calls: benchmarks/results/gpu.md) runs beside the CPU engine's
# (phaseimpact warmup) and then beside scale.py, which times 1 to 16 threads on the other 15
# cores; gpu.py's CPU rows come after its GPU rows. Results land in benchmarks/results/ and are
# copied to $OUT (default ./gpu-machine-out) with the logs.
#
# The image's numba-cuda (0.30.4, seen 2026-11-28) fails with its numpy 2.5 (numpy removed
# np.row_stack, which that numba-cuda still overloads): carry a numpy 2.4 wheel for Python 3.12 in
# .whl/ and install it first (the device tool's README says how), as the first line below shows.
#
#     [ -d .whl ] && python3 -m pip install -q --no-index --no-deps --target /tmp/site .whl/*.whl \
#         && export PYTHONPATH=/tmp/site
#     bash benchmarks/gpu_machine.sh [--quick] [--only gpu|scale]
#         # --quick: a 300 x 300 GPU grid, scale.py --quick; --only: one of the two parts
set -u
OUT=${OUT:-$PWD/gpu-machine-out}
mkdir -p "$OUT"
PY=${PYTHON:-python3}
export PYTHONUNBUFFERED=1 PYTHONPATH=$PWD${PYTHONPATH:+:$PYTHONPATH}
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-/tmp/phaseimpact-numba}
side=1000 quick= only=
while [ $# -gt 0 ]; do
    case $1 in
        --quick) side=300 quick=--quick ;;
        --only) only=$2; shift ;;
        *) echo "usage: $0 [--quick] [--only gpu|scale]" >&2; exit 2 ;;
    esac
    shift
done
stamp() { echo "== $(date -u +%T) $*"; }
save() { cp benchmarks/results/"$1".md benchmarks/results/"$1".json "$OUT"/ 2>/dev/null; }

{
    stamp "machine"
    echo "cores: $(nproc)"
    nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader || true
    "$PY" -c 'import sys, importlib.metadata as m
def version(name):
    try:
        return m.version(name)
    except m.PackageNotFoundError:
        return "none"
print("Python", sys.version.split()[0], *(f"{p} {version(p)}" for p in ("numpy", "scipy", "numba", "numba-cuda", "llvmlite", "h5py", "joblib")))'
    # outside the tested numba range the linked-only hooks are not trusted: numba's own compile
    "$PY" -c 'import numba, sys; sys.exit(0 if (0, 59) <= tuple(map(int, numba.__version__.split(".")[:2])) < (0, 69) else 1)' \
        || { export PHASEIMPACT_LINKED_ONLY=0; echo "numba outside 0.59-0.68: PHASEIMPACT_LINKED_ONLY=0"; }

    gpu=
    if [ "$only" != scale ]; then
        stamp "gpu.py --side $side --threads 16 (in the background) and the CPU engine's first compile"
        timeout 560 "$PY" benchmarks/gpu.py --side "$side" --threads 16 >"$OUT/gpu.txt" 2>&1 &
        gpu=$!
    fi
    start=$(date +%s%N)
    "$PY" -m phaseimpact warmup
    echo "warmup exit $? after $(( ($(date +%s%N) - start) / 1000000 )) ms wall"

    if [ "$only" != gpu ]; then
        stamp "scale.py --section scale_gpu_machine $quick (the kernel compiling on one core beside it)"
        timeout 300 "$PY" benchmarks/scale.py --section scale_gpu_machine $quick
        echo "scale.py exit $?"
        save scale_gpu_machine
        save scale_gpu_machine_quick
    fi

    if [ -n "$gpu" ]; then
        stamp "waiting for gpu.py"
        wait "$gpu"
        echo "gpu.py exit $?"
        cat "$OUT/gpu.txt"
        save gpu
    fi
    stamp "done"
} 2>&1 | tee "$OUT/log.txt"

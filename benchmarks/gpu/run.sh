#!/usr/bin/env bash
# Run ON THE LENT GPU MACHINE (the device tool, carry [".gl", ".whl"]) from the repository root,
# after benchmarks/gpu/prepare.sh ran here. Takes the real-GPU figures of the issues in one call:
#   core:   fps at 3840×2160 with >= 4 M visible voxels (640³), and the usual sizes
#   iso:    fps for 100³ at 3840×2160 and 512³ (--full adds 512³)
#   stacks: Mrays/s of the five layouts against the paper's GTX 970 tables
# PARTS (default "core iso stacks") and BENCH_ARGS (default "--no-peers") override. The results
# (RESULTS.md sections, results/*.json, the Fig. 5 plot) come back under $OUT/bench; merge the
# sections into benchmarks/RESULTS.md here (harness.replace_section, or copy between markers).
set -uo pipefail
if [ -d .gl ] && command -v nvidia-smi >/dev/null; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
egl=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f "$egl" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$egl"
if [ -d .whl ]; then
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/site .whl/*.whl || exit 1
fi
export PYTHONPATH="$PWD/src:/tmp/site${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1
out="${OUT:-/tmp/geoshade-gpu}/bench"
mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader || true
python3 -m geoshade.cli.main info --gl || exit 1
for part in ${PARTS:-core iso stacks}; do
    echo "=== geoshade bench $part ${BENCH_ARGS:---no-peers}"
    # shellcheck disable=SC2086
    python3 -m geoshade.cli.main bench "$part" ${BENCH_ARGS:---no-peers} -o "$out" 2>&1 \
        | tail -n 40
done
ls -l "$out" "$out/results" 2>/dev/null

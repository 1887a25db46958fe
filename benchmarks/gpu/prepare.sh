#!/usr/bin/env bash
# Run HERE (the development machine, with the package registries), from the repository root,
# before a GPU session: fetches what the lent GPU machine lacks into two git-ignored folders that
# the device tool carries: .gl (NVIDIA's EGL goes through glvnd: libEGL/libOpenGL loaders) and
# .whl (moderngl and glcontext for the machine's Python 3.12). Everything else the benchmarks
# import is already there (numpy, numba, matplotlib, tifffile, xarray, pandas, pyarrow, h5py).
set -euo pipefail
cd "$(git rev-parse --show-toplevel)"
grep -qx '/.gl/' .git/info/exclude || echo /.gl/ >> .git/info/exclude
grep -qx '/.whl/' .git/info/exclude || echo /.whl/ >> .git/info/exclude
mkdir -p .gl .whl /tmp/amd64/partial
o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
apt-get $o update -qq
(cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
plat=(--platform manylinux_2_28_x86_64 --platform manylinux_2_17_x86_64
      --platform manylinux2014_x86_64 --platform manylinux1_x86_64)
for pkg in "moderngl==$(python -c 'import moderngl; print(moderngl.__version__)')" \
           "glcontext==$(python -c 'import importlib.metadata as m; print(m.version("glcontext"))')"; do
    python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 \
        --implementation cp "${plat[@]}" -d .whl "$pkg"
done
du -sh .gl .whl
echo "ready: call the device tool's run with carry [\".gl\", \".whl\"] and the command" \
     "'bash benchmarks/gpu/run.sh'"

# Sourced by the scripts: installs the system package and the Python tools the project needs.
VENV="$PWD/.venv"

step() { printf '\n==> %s\n' "$*"; }

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else
    echo "need root to run: $*" >&2; return 1; fi
}

# libclang: fmi-sys generates its FMI 2.0 bindings with bindgen at build time.
if ! ldconfig -p 2>/dev/null | grep -q 'libclang\(-[0-9.]*\)\?\.so'; then
  step "installing libclang-dev (needed by fmi-sys/bindgen)"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libclang-dev >/dev/null
fi

# fmpy in a local virtual environment (validation and the cross-checks).
if [ ! -x "$VENV/bin/fmpy" ]; then
  step "creating $VENV with fmpy"
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install -q --upgrade pip >/dev/null
  "$VENV/bin/pip" install -q "fmpy==0.3.32" >/dev/null
fi

# pythonfmu packages a Python class as an FMU: tests/fmpy/make_pythonfmu.py builds a test FMU
# whose binary this project did not write (tests/tests/foreign_fmus.rs, master_vs_fmpy.rs).
if ! "$VENV/bin/python" -c "import pythonfmu" 2>/dev/null; then
  step "installing pythonfmu into $VENV"
  "$VENV/bin/pip" install -q "pythonfmu==0.7.0" >/dev/null
fi

# The Python package railfmu (python/): maturin builds its wheel from the binding crate; pandas,
# dask.distributed, tqdm and pytest are what it and its tests use; pyarrow reads the Parquet
# results (pandas.read_parquet).
if ! "$VENV/bin/python" -c "import maturin, pandas, distributed, tqdm, pytest, pyarrow" 2>/dev/null; then
  step "installing maturin, pandas, pyarrow, dask.distributed, tqdm, pytest into $VENV"
  "$VENV/bin/pip" install -q "maturin==1.16.0" "pandas==3.1.1" "pyarrow==26.0.1" "dask==2026.8.0" \
    "distributed==2026.8.0" "tqdm==4.67.1" "pytest==9.2.0" >/dev/null
fi

# SSP hosts for tests/tests/ssp_interop.rs and the benchmark's peers: libcosim (libcosimpy,
# whose libcosimc needs the system's oneTBB runtime libtbb12) and Ecos (ecospy) run the
# exported SSPs.
if ! ldconfig -p 2>/dev/null | grep -q 'libtbb\.so\.12'; then
  step "installing libtbb12 (needed by libcosimpy)"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libtbb12 >/dev/null
fi
if ! "$VENV/bin/python" -c "import libcosimpy, ecospy" 2>/dev/null; then
  step "installing libcosimpy and ecospy into $VENV"
  "$VENV/bin/pip" install -q "libcosimpy==0.0.6" "ecospy==0.7.2" >/dev/null
fi

# Portable Linux binaries: cargo-zigbuild builds the FMUs against glibc 2.17 (manylinux2014)
# with zig as C compiler and linker. Both are pinned: cargo-zigbuild from crates.io into
# target/tools/bin (where package-fmus looks first), zig from PyPI's ziglang package in the venv,
# which cargo-zigbuild runs as `$CARGO_ZIGBUILD_PYTHON_PATH -m ziglang`.
ZIGBUILD_VERSION=0.24.1
ZIGLANG_VERSION=0.15.2
TOOLS="$PWD/target/tools"
if [ "$("$TOOLS/bin/cargo-zigbuild" --version 2>/dev/null)" != "cargo-zigbuild $ZIGBUILD_VERSION" ]; then
  step "installing cargo-zigbuild $ZIGBUILD_VERSION into $TOOLS"
  cargo install -q cargo-zigbuild --version "$ZIGBUILD_VERSION" --locked --root "$TOOLS"
fi
if [ "$("$VENV/bin/python" -m ziglang version 2>/dev/null)" != "$ZIGLANG_VERSION" ]; then
  step "installing zig $ZIGLANG_VERSION (PyPI ziglang) into $VENV"
  "$VENV/bin/pip" install -q "ziglang==$ZIGLANG_VERSION" >/dev/null
fi
export PATH="$TOOLS/bin:$PATH"
export CARGO_ZIGBUILD_PYTHON_PATH="$VENV/bin/python"

# Builds the FMU libraries with cargo-zigbuild (glibc 2.17) and writes dist/*.fmu.
package_fmus() {
  cargo run --release -q -p model-description --bin package-fmus
}

# pyo3 (python/) builds against the venv's interpreter, the same for maturin and clippy.
export PYO3_PYTHON="$VENV/bin/python"

# Builds the railfmu wheel (python/, maturin, release) into target/wheels and installs it into
# the venv.
python_package() {
  rm -f target/wheels/railfmu-*.whl
  "$VENV/bin/maturin" build --release --quiet -m python/Cargo.toml -i "$VENV/bin/python" -o target/wheels
  "$VENV/bin/pip" install -q --force-reinstall --no-deps target/wheels/railfmu-*.whl
}

# Sourced by the OpenSees benchmarks: sets $py to a Python with openseespy
# ($OPENSEES_PYTHON, default python3.12; pyenv installs keep python3.12
# behind a version selector, so PYENV_VERSION defaults to 3.12.1), or
# exits 2 saying how to install it.
py="${OPENSEES_PYTHON:-python3.12}"
if ! command -v "$py" >/dev/null 2>&1 || ! "$py" -c "import openseespy" >/dev/null 2>&1; then
  export PYENV_VERSION="${PYENV_VERSION:-3.12.1}"
fi
"$py" -c "import openseespy" >/dev/null 2>&1 || {
  echo "OpenSeesPy not found: python3.12 -m pip install openseespy==3.8.0.0 numpy (or set OPENSEES_PYTHON)" >&2
  exit 2
}

#!/usr/bin/env bash
# Builds the Python module with `pip install .` into a virtual environment of Debian's
# /usr/bin/python3 (build/python-venv, with the system's site packages: Debian's numpy, pytest
# and matplotlib) and runs its tests (python/tests) with pytest. Offline: nothing is downloaded
# (--no-index; the build backend needs nothing beyond the Debian packages of install-deps.sh).
# Called by scripts/test.sh; exits with pytest's status.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "${repo_root}"

python=/usr/bin/python3  # the interpreter Debian's python3-numpy and pybind11 belong to
venv="build/python-venv"

if [[ ! -x "${venv}/bin/python" ]]; then
  "${python}" -m venv --system-site-packages "${venv}"
fi
"${venv}/bin/python" -m pip install --no-index --disable-pip-version-check --quiet .
cd python/tests  # not the source tree's package: the installed one is tested
exec "${repo_root}/${venv}/bin/python" -m pytest -q -p no:cacheprovider .

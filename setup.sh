#!/usr/bin/env bash
# Set up traj2events on a fresh Debian/Ubuntu machine: system packages (if missing), then
# a .venv with the package and its pinned dependencies. Idempotent: a second run with
# nothing changed only checks and returns.
#   bash setup.sh            # the pipeline: pip install -e ".[pipeline]"
#   bash setup.sh --test     # the pipeline + test dependencies
set -euo pipefail
cd "$(dirname "$0")"

extras="[pipeline]" ; [[ "${1:-}" == "--test" ]] && extras="[pipeline,test]"

need_apt=()
command -v python3 >/dev/null || need_apt+=(python3)
python3 -c "import ensurepip, venv" 2>/dev/null || need_apt+=(python3-venv)
command -v git >/dev/null || need_apt+=(git)
command -v ffmpeg >/dev/null || need_apt+=(ffmpeg)                     # video (FFV1, H.264)
{ ldconfig -p || /sbin/ldconfig -p; } 2>/dev/null | grep -q libOSMesa.so || need_apt+=(libosmesa6)  # headless OpenGL on the CPU
{ ldconfig -p || /sbin/ldconfig -p; } 2>/dev/null | grep -q libEGL_mesa.so || need_apt+=(libegl1 libegl-mesa0)  # EGL (render.backend)
if [[ "$extras" == *test* ]]; then command -v h5dump >/dev/null || need_apt+=(hdf5-tools); fi  # tests read the files as C users do
if [[ "$extras" == *test* ]]; then command -v chromium >/dev/null || need_apt+=(chromium); fi  # the overview, read in a browser
if ((${#need_apt[@]})); then
  echo "setup: installing system packages: ${need_apt[*]}"
  SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_apt[@]}" python3-dev >/dev/null
fi

[[ -x .venv/bin/python ]] || python3 -m venv .venv
# Reinstall only when the package's requirements change.
stamp=".venv/.traj2events-setup"
want="$(cat pyproject.toml setup.sh | sha256sum | cut -d' ' -f1)$extras"
if [[ "$(cat "$stamp" 2>/dev/null)" != "$want" ]]; then
  echo "setup: installing Python packages into .venv"
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q -e ".$extras"
  if [[ "$extras" == *test* ]]; then
    # PyTorch's CPU build, for the tested DataLoader example in docs/dataset.md (the
    # package never imports torch). PyPI's own torch wheel pulls in CUDA (GBs): the CPU
    # build comes from a local wheel store or PyTorch's index, else that test is skipped.
    .venv/bin/python -m pip install -q "torch==2.13.0+cpu" 2>/dev/null ||
      .venv/bin/python -m pip install -q --timeout 20 --retries 1 "torch==2.13.0+cpu" \
        --extra-index-url https://download.pytorch.org/whl/cpu 2>/dev/null ||
      echo "setup: no CPU build of torch found; the DataLoader example test will be skipped"
  fi
  echo "$want" > "$stamp"
fi
.venv/bin/traj2events --version

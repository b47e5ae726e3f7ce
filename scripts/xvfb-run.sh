#!/usr/bin/env bash
# Runs a command under a fresh virtual X display (Xvfb), for headless machines.
#
#   scripts/xvfb-run.sh cargo run --release -- view
#   scripts/xvfb-run.sh target/debug/radiosity view cornell --screenshot out.png --after-shots 200
#
# Xvfb picks a free display number itself (-displayfd), so several runs can share a machine.
# XDG_RUNTIME_DIR is set to a private directory of mode 700 when the caller has none, because
# winit and Mesa warn or fail without one. WAYLAND_DISPLAY is cleared so winit uses X11.
# Screen size: XVFB_SCREEN (default 1280x800x24). Exits with the command's status.
set -euo pipefail

if [ $# -eq 0 ]; then
  echo "usage: $0 COMMAND [ARGS...]" >&2
  exit 2
fi
if ! command -v Xvfb >/dev/null; then
  echo "$0: Xvfb not found; run ./setup.sh (it installs the xvfb package)" >&2
  exit 127
fi

workdir=$(mktemp -d)
chmod 700 "$workdir"
xvfb_pid=""
cmd_pid=""
cleanup() {
  if [ -n "$cmd_pid" ]; then
    kill "$cmd_pid" 2>/dev/null || true
  fi
  if [ -n "$xvfb_pid" ]; then
    kill "$xvfb_pid" 2>/dev/null || true
    wait "$xvfb_pid" 2>/dev/null || true
  fi
  rm -rf "$workdir"
}
trap cleanup EXIT
# On a signal, end the command and the display now, not when the command ends by itself.
trap 'exit 143' TERM
trap 'exit 130' INT

mkfifo "$workdir/displayfd"
Xvfb -displayfd 3 -screen 0 "${XVFB_SCREEN:-1280x800x24}" -nolisten tcp -noreset \
  3>"$workdir/displayfd" 2>"$workdir/xvfb.log" &
xvfb_pid=$!
# Xvfb writes the display number it chose once it accepts connections.
if ! read -r -t 30 display <"$workdir/displayfd"; then
  echo "$0: Xvfb did not start:" >&2
  cat "$workdir/xvfb.log" >&2
  exit 1
fi

export DISPLAY=":$display"
unset WAYLAND_DISPLAY
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "$XDG_RUNTIME_DIR" ]; then
  mkdir -p "$workdir/runtime"
  chmod 700 "$workdir/runtime"
  export XDG_RUNTIME_DIR="$workdir/runtime"
fi

# The command runs in the background so a signal to this script is handled at once (bash
# runs traps only between foreground commands); its stdin stays the script's.
set +e
"$@" <&0 &
cmd_pid=$!
wait "$cmd_pid"
status=$?
cmd_pid=""
set -e
exit "$status"

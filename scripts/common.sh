# Shared by scripts/test and scripts/demo (sourced, not run).
# The catkin workspace lives in .ws/ at the repository root (AMYTISS_WS overrides); the package
# (the repository root) is linked into its src/ so the checkout itself is what gets built.
AMYTISS_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
AMYTISS_WS=${AMYTISS_WS:-$AMYTISS_ROOT/.ws}
# ROS tools need Debian's python3 (a pyenv python3 may come first on PATH and lacks catkin).
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
export ROS_HOME=${ROS_HOME:-$AMYTISS_WS/ros_home}
AMYTISS_JOBS=${AMYTISS_JOBS:-$(nproc)}

amytiss_install() {
  "$AMYTISS_ROOT/scripts/install-deps"
}

amytiss_workspace() {
  mkdir -p "$AMYTISS_WS/src" "$ROS_HOME"
  amytiss_link "$AMYTISS_WS/src/amytiss" "$AMYTISS_ROOT"
  # A workspace made when the messages were a package of their own still links it.
  if [ -L "$AMYTISS_WS/src/amytiss_msgs" ]; then rm -f "$AMYTISS_WS/src/amytiss_msgs"; fi
}

amytiss_link() {
  local link=$1 target=$2
  if [ "$(readlink -f "$link" 2>/dev/null)" != "$target" ]; then
    rm -rf "$link"
    ln -s "$target" "$link"
  fi
}

# catkin_make with the given extra targets (none: build everything but the tests).
amytiss_catkin_make() {
  amytiss_workspace
  (cd "$AMYTISS_WS" && catkin_make -j"$AMYTISS_JOBS" \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release "$@")
}

amytiss_source() {
  # setup.bash reads unset variables; relax nounset while sourcing.
  set +u
  # shellcheck disable=SC1091
  source "$AMYTISS_WS/devel/setup.bash"
  set -u
}

# Shared by scripts/test and scripts/demo (sourced, not run).
# The catkin workspace lives in .ws/ at the repository root (AMYTISS_WS overrides); the package
# is linked into its src/ so the checkout itself is what gets built.
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
  local link="$AMYTISS_WS/src/amytiss"
  if [ "$(readlink -f "$link" 2>/dev/null)" != "$AMYTISS_ROOT" ]; then
    rm -rf "$link"
    ln -s "$AMYTISS_ROOT" "$link"
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

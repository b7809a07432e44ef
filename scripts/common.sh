# Shared set-up for the scripts in this folder; sourced, not run.
#   DRB_WORKSPACE   catkin workspace to build in (default: <repo>/.build/ws, git-ignored)
#   DRB_JOBS        parallel build jobs (default: nproc)
set -euo pipefail

# The first python3 on PATH may be a private interpreter without catkin_pkg:
# ROS and catkin tools must find Debian's.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:${PATH}"

DRB_REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DRB_WORKSPACE="${DRB_WORKSPACE:-${DRB_REPO}/.build/ws}"
DRB_JOBS="${DRB_JOBS:-$(nproc)}"

# Debian 12 packages: ROS 1 from Debian (no /opt/ros), the core's libraries,
# the oracles and peers (MPFR, KDL, MuJoCo) and the test tools.
DRB_APT_PACKAGES=(
  build-essential cmake pkg-config
  catkin libroscpp-dev libroslib-dev libtf2-ros-dev liburdfdom-dev librostest-dev libgtest-dev googletest
  python3-rostest python3-roslaunch python3-rosservice python3-rosnode python3-rostopic rosbash
  ros-message-generation ros-message-runtime ros-std-msgs ros-geometry-msgs ros-visualization-msgs libvisualization-msgs-dev python3-visualization-msgs libtf2-msgs-dev python3-tf2-msgs python3-std-msgs python3-geometry-msgs python3-tf2-ros
  libeigen3-dev libassimp-dev libtinyxml2-dev
  libmpfrc++-dev libmpfr-dev libgmp-dev liborocos-kdl-dev libkdl-parser-dev libmujoco-dev libbenchmark-dev
  python3-numpy python3-yaml
  python3-matplotlib
  # clients and rviz: the Python client, rviz, and the headless screenshot
  # (xvfb-run needs xauth; software OpenGL comes from the Mesa DRI drivers)
  python3-rospy rviz xvfb xauth imagemagick libgl1-mesa-dri
  # reliability: libFuzzer targets (clang, libFuzzer and the sanitizer
  # runtimes) and symbolised sanitizer reports (scripts/fuzz)
  clang libclang-rt-14-dev llvm
)

drb_log() { printf '\033[1m[diff_rigid_body]\033[0m %s\n' "$*" >&2; }

# Installs the missing packages with apt; does nothing when all are present.
drb_setup() {
  local missing=()
  local pkg
  for pkg in "${DRB_APT_PACKAGES[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
  done
  if ((${#missing[@]} == 0)); then
    return 0
  fi
  drb_log "installing: ${missing[*]}"
  local sudo=()
  [[ $(id -u) -eq 0 ]] || sudo=(sudo)
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# Builds the package in a catkin workspace whose src/ links to this checkout.
drb_build() {
  mkdir -p "${DRB_WORKSPACE}/src"
  ln -sfn "${DRB_REPO}" "${DRB_WORKSPACE}/src/diff_rigid_body"
  # The default workspace lives inside the checkout: keep rospack and catkin
  # from crawling back into it through the src/ link ("File system loop").
  if [[ -d "${DRB_REPO}/.build" ]]; then
    touch "${DRB_REPO}/.build/CATKIN_IGNORE" "${DRB_REPO}/.build/rospack_nosubdirs"
  fi
  drb_log "building in ${DRB_WORKSPACE}"
  (cd "${DRB_WORKSPACE}" && catkin_make -DCMAKE_BUILD_TYPE=Release "$@" -j"${DRB_JOBS}" >&2)
  # shellcheck disable=SC1091
  set +u
  source "${DRB_WORKSPACE}/devel/setup.bash"
  set -u
}

# Shared set-up for the scripts in this folder; sourced, not run.
#   DRB_WORKSPACE   catkin workspace to build in (default: outside the checkout,
#                   ${XDG_CACHE_HOME:-~/.cache}/diff_rigid_body/ws-<checkout name>-<hash of its path>;
#                   scripts/workspace prints it)
#   DRB_JOBS        parallel build jobs (default: nproc)
#   DRB_SKIP_BUILD  1: drb_build only sources an existing workspace (no catkin_make)
set -euo pipefail

# The first python3 on PATH may be a private interpreter without catkin_pkg:
# ROS and catkin tools must find Debian's.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:${PATH}"

DRB_REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)"
# The workspace's src/ links to the checkout, so it must not lie inside it:
# rosrun and rospack follow links (find -L) and would loop back into it.
drb_default_workspace() {
  local hash
  hash="$(printf '%s' "${DRB_REPO}" | sha1sum | cut -c1-10)"
  printf '%s/diff_rigid_body/ws-%s-%s\n' "${XDG_CACHE_HOME:-${HOME}/.cache}" "$(basename "${DRB_REPO}")" "${hash}"
}
DRB_WORKSPACE="${DRB_WORKSPACE:-$(drb_default_workspace)}"
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
  python3-numpy python3-yaml python3-scipy
  # diff_rigid_body._local: the core in process (pybind11; LocalScene); batches over Dask (dask_batches)
  pybind11-dev python3-pybind11 python3-distributed
  # diff_rigid_body.torch, its rostest, the trajectory demo and bench/client_trajectory.py
  python3-torch
  # joint_states (sensor_msgs/JointState); demo.launch joint_state_publisher:=true|gui
  ros-sensor-msgs python3-sensor-msgs libsensor-msgs-dev joint-state-publisher joint-state-publisher-gui
  python3-matplotlib
  # clients and rviz: the Python client, rviz, and the headless screenshot
  # (xvfb-run needs xauth; software OpenGL comes from the Mesa DRI drivers)
  python3-rospy rviz xvfb xauth imagemagick libgl1-mesa-dri
  # tf from the command line: rosrun tf2_tools echo.py (README; Debian ships no tf_echo)
  tf2-tools
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

# Builds the package in a catkin workspace whose src/ links to this checkout,
# then sources its devel space. With DRB_SKIP_BUILD=1 it only sources it.
drb_build() {
  case "$(realpath -m "${DRB_WORKSPACE}")/" in
    "${DRB_REPO}/"*)
      drb_log "DRB_WORKSPACE ${DRB_WORKSPACE} lies inside the checkout: rosrun and rospack will find" \
        "the package again through src/diff_rigid_body (file system loop); choose a path outside ${DRB_REPO}"
      return 1 ;;
  esac
  if [[ -d "${DRB_REPO}/.build/ws/src" ]]; then
    drb_log "warning: ${DRB_REPO}/.build holds a workspace of an older version (inside the checkout);" \
      "remove it (rm -rf .build): rospack and rosrun follow its src/ link back into the checkout"
  fi
  if [[ "${DRB_SKIP_BUILD:-0}" == 1 ]]; then
    if [[ ! -f "${DRB_WORKSPACE}/devel/setup.bash" ]]; then
      drb_log "DRB_SKIP_BUILD=1 but ${DRB_WORKSPACE} has not been built (no devel/setup.bash)"
      return 1
    fi
    drb_log "using the workspace ${DRB_WORKSPACE} as built (DRB_SKIP_BUILD=1)"
  else
    mkdir -p "${DRB_WORKSPACE}/src"
    ln -sfn "${DRB_REPO}" "${DRB_WORKSPACE}/src/diff_rigid_body"
    drb_log "building in ${DRB_WORKSPACE}"
    (cd "${DRB_WORKSPACE}" && catkin_make -DCMAKE_BUILD_TYPE=Release "$@" -j"${DRB_JOBS}" >&2)
  fi
  # shellcheck disable=SC1091
  set +u
  source "${DRB_WORKSPACE}/devel/setup.bash"
  set -u
}

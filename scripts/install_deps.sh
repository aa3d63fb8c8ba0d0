#!/usr/bin/env bash
# Installs the Debian 12 packages extwrench needs, only those missing. Safe to run again.
set -euo pipefail
packages=(
  build-essential cmake make git pkg-config
  libeigen3-dev libtinyxml2-dev libyaml-cpp-dev libcli11-dev libassimp-dev libembree-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  liborocos-kdl-dev libkdl-parser-dev libmujoco-dev
  # MuJoCo's CMake config requires OpenGL (find_dependency), which libmujoco-dev only recommends.
  libgl-dev libopengl-dev libglx-dev
  # assimp's CMake targets link libz.so, which libassimp-dev does not pull in.
  zlib1g-dev
  gnuplot-nox
  # The fuzz harnesses (make fuzz, make test-sanitize): clang, and its libFuzzer and sanitizer
  # runtimes, which clang-14 only recommends.
  clang libclang-rt-14-dev
  # The Python module (docs/python.md): pybind11 and the interpreter's headers to build it,
  # numpy at run time, pytest for tests/python, matplotlib for examples/python.
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "extwrench: installing missing Debian packages: ${missing[*]}"
  sudo_cmd=""
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

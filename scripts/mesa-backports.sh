#!/usr/bin/env bash
# Installs a second Mesa (bookworm-backports, 25.0.7 when written) into a private prefix, for the
# portability check and the noise model. The system Mesa is not touched: nothing is installed
# with dpkg, and apt reads its own sources list and package lists from the prefix.
#
#   scripts/mesa-backports.sh [PREFIX]          default: target/mesa-backports
#   . PREFIX/env.sh                              then every process in that shell uses it
#
# PREFIX/env.sh (and PREFIX/env.list, the same as KEY=value lines) sets LD_LIBRARY_PATH (libEGL_mesa, libgallium, libdrm), LIBGL_DRIVERS_PATH and
# VK_DRIVER_FILES (a copy of lavapipe's ICD file whose library_path is absolute). glvnd's
# libEGL.so.1 and the Vulkan loader stay the system's; they find this Mesa through those
# variables. Needs the network (deb.debian.org) once; a second run reuses the prefix.
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=$(realpath -m "${1:-target/mesa-backports}")
version=${MESA_BACKPORTS_VERSION:-25.0.7-2~bpo12+1}
arch=$(dpkg --print-architecture)
triplet=$(gcc -print-multiarch 2>/dev/null || echo x86_64-linux-gnu)
lib="$prefix/root/usr/lib/$triplet"

if [ -f "$prefix/env.list" ] && [ "$(cat "$prefix/version" 2>/dev/null)" = "$version" ]; then
  echo "Mesa $version already in $prefix (. $prefix/env.sh)"
  exit 0
fi

apt_dir="$prefix/apt"
mkdir -p "$apt_dir/lists/partial" "$apt_dir/debs" "$prefix/root"
echo "deb http://deb.debian.org/debian bookworm-backports main" >"$apt_dir/sources.list"
apt_options=(
  -o "Dir::Etc::SourceList=$apt_dir/sources.list"
  -o "Dir::Etc::SourceParts=/dev/null"
  -o "Dir::State::Lists=$apt_dir/lists"
  -o "Dir::Cache=$apt_dir/cache"
  -o "APT::Architecture=$arch"
  -o "APT::Sandbox::User=root"
)
mkdir -p "$apt_dir/cache/archives/partial"
echo "fetching the bookworm-backports package lists ..."
apt-get "${apt_options[@]}" update -qq

# What llvmpipe (EGL + GL) and lavapipe (Vulkan) need of a newer Mesa; the libdrm they are
# linked against comes from backports too. LLVM (libllvm15) is the system's: the backport links
# the same one.
packages=(
  "libgl1-mesa-dri=$version" "mesa-libgallium=$version" "libegl-mesa0=$version"
  "mesa-vulkan-drivers=$version" "libgbm1=$version"
)
drm=$(apt-cache "${apt_options[@]}" show libdrm2 | sed -n 's/^Version: //p' | grep bpo | head -n 1)
if [ -n "$drm" ]; then
  packages+=("libdrm2=$drm" "libdrm-amdgpu1=$drm" "libdrm-intel1=$drm" "libdrm-common=$drm")
fi
echo "downloading ${packages[*]}"
(cd "$apt_dir/debs" && apt-get "${apt_options[@]}" download -qq "${packages[@]}")
for deb in "$apt_dir"/debs/*.deb; do
  dpkg -x "$deb" "$prefix/root"
done

icd=$(ls "$prefix"/root/usr/share/vulkan/icd.d/lvp_icd*.json | head -n 1)
sed "s#\"library_path\": *\"[^\"]*/\\?\\(libvulkan_lvp.so\\)\"#\"library_path\": \"$lib/\\1\"#" \
  "$icd" >"$prefix/lvp_icd.json"
grep -q "\"library_path\": \"$lib/libvulkan_lvp.so\"" "$prefix/lvp_icd.json" || {
  echo "error: could not point $prefix/lvp_icd.json at $lib/libvulkan_lvp.so" >&2
  exit 1
}

cat >"$prefix/env.sh" <<EOF
# Mesa $version from bookworm-backports, private prefix (written by scripts/mesa-backports.sh).
export LD_LIBRARY_PATH="$lib\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
export LIBGL_DRIVERS_PATH="$lib/dri"
export VK_DRIVER_FILES="$prefix/lvp_icd.json"
export VK_ICD_FILENAMES="$prefix/lvp_icd.json"
EOF
# The same variables as KEY=value lines, for `harness noise` (which sets them on its children).
sed -n 's/^export \([A-Z_]*\)="\(.*\)"$/\1=\2/p' "$prefix/env.sh" |
  sed "s#\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}##" >"$prefix/env.list"
echo "$version" >"$prefix/version"
echo "Mesa $version in $prefix; use it with: . $prefix/env.sh"

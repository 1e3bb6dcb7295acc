#!/usr/bin/env bash
# Builds histencil into a driver's test container, in the shape of Mesa's
# .gitlab-ci/container/build-*.sh: a pinned ref, a locked release build, the binary and the
# suite entry installed into a prefix, the build tree removed. Copy it beside your other build
# scripts and pin HISTENCIL_REF; the container then runs histencil as the `bin` of the
# [[gtest]] entry in ci/mesa/histencil.toml.
#
# Needs: git, a Rust toolchain (cargo, 1.82 or later), glslc (shaderc) and the Vulkan headers'
# loader library to link against (libvulkan-dev). At run time histencil needs only a Vulkan
# loader, the driver under test and the Khronos validation layer (VK_LAYER_PATH).
#
# Variables:
#   HISTENCIL_GIT_URL   where histencil's repository is (required)
#   HISTENCIL_REF       the commit or tag to build (pin it: the baselines are for one version)
#   HISTENCIL_PREFIX    where it goes (default /histencil): bin/histencil and
#                       share/histencil/histencil.toml
#   HISTENCIL_SRC       build this checkout instead of cloning (then nothing is removed)
#   HISTENCIL_PROFILE   cargo profile (default release)
#   HISTENCIL_PREBUILT  install this binary of the ref instead of building one (tools/suite-proof
#                       installs the one its tests ran: a second build takes minutes)

set -euo pipefail
set -x

HISTENCIL_REF="${HISTENCIL_REF:?pin the histencil commit or tag to build}"
HISTENCIL_PREFIX="${HISTENCIL_PREFIX:-/histencil}"
HISTENCIL_PROFILE="${HISTENCIL_PROFILE:-release}"

if [[ -n "${HISTENCIL_SRC:-}" ]]; then
  src=$HISTENCIL_SRC
  [[ $(git -C "$src" rev-parse HEAD) == $(git -C "$src" rev-parse "$HISTENCIL_REF^{commit}") ]] || {
    echo "build-histencil.sh: $src is not at $HISTENCIL_REF" >&2
    exit 1
  }
  cleanup=
else
  src=$(mktemp -d /tmp/histencil-build.XXXXXX)
  git clone --quiet "${HISTENCIL_GIT_URL:?the URL of the histencil repository}" "$src"
  git -C "$src" checkout --quiet --detach "$HISTENCIL_REF"
  cleanup=$src
fi

if [[ -n "${HISTENCIL_PREBUILT:-}" ]]; then
  binary=$HISTENCIL_PREBUILT
else
  # The lockfile as committed: the same crates the ref was tested with.
  cargo build --manifest-path "$src/Cargo.toml" --locked --profile "$HISTENCIL_PROFILE" \
    --bin histencil
  target_dir=$(cargo metadata --manifest-path "$src/Cargo.toml" --format-version 1 --no-deps |
    sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
  profile_dir=$HISTENCIL_PROFILE
  [[ $profile_dir == dev ]] && profile_dir=debug
  binary=$target_dir/$profile_dir/histencil
fi

mkdir -p "$HISTENCIL_PREFIX/bin" "$HISTENCIL_PREFIX/share/histencil"
install -m 755 "$binary" "$HISTENCIL_PREFIX/bin/histencil"
install -m 644 "$src/ci/mesa/histencil.toml" "$HISTENCIL_PREFIX/share/histencil/histencil.toml"
git -C "$src" rev-parse HEAD >"$HISTENCIL_PREFIX/share/histencil/REVISION"

if [[ -n $cleanup ]]; then
  rm -rf "$cleanup"
fi
"$HISTENCIL_PREFIX/bin/histencil" --version

#!/usr/bin/env bash
# Installs this build into a fresh prefix and builds examples/consumer against it twice: through
# find_package(seamcl CONFIG) and through pkg-config. Fails when a public header reaches a private
# one, when a dependency is not exported, when a private header is installed, or when the
# consumer's render is not what it should be.
#   consumer_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
source=$2
work=$build/consumer-test
rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix

fail() { echo "FAIL: $*" >&2; exit 1; }

echo "== install into $prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
libdir=$(ls -d "$prefix"/lib*/cmake/seamcl | head -1)
libdir=${libdir%/cmake/seamcl}
for f in "$prefix/bin/seamcl" "$libdir/cmake/seamcl/seamclConfig.cmake" "$libdir/cmake/seamcl/seamclTargets.cmake" \
         "$libdir/pkgconfig/seamcl.pc" "$prefix/include/seamcl/pipeline/renderer.h" "$prefix/include/seamcl/version.h" \
         "$prefix/include/seamcl/kernels/seamcl_types.h"; do
  [ -e "$f" ] || fail "not installed: $f"
done
ls "$libdir"/libseamcl.* >/dev/null 2>&1 || fail "no libseamcl in $libdir"
[ -f "$libdir/seamcl/libseamcl_oiio.so" ] || fail "no OpenImageIO module in $libdir/seamcl"
# The consumer writes PNGs through the installed module: a prefix other than the configured one
# names it (host/io/image_codec.h).
export SEAMCL_OIIO_MODULE="$libdir/seamcl/libseamcl_oiio.so"
for private in pipeline/stages/raster_twin.h cl/kernel_sources.h pipeline/adjacency.h core/srgb.h io/texture_file.h; do
  [ ! -e "$prefix/include/seamcl/$private" ] || fail "private header installed: $private"
done
"$prefix/bin/seamcl" --version | grep -q "^seamcl " || fail "installed seamcl --version"

echo "== consumer through find_package(seamcl CONFIG)"
cmake -S "$source/examples/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >"$work/configure.log" 2>&1 \
  || { cat "$work/configure.log"; fail "consumer configure"; }
grep -q "public headers under" "$work/configure.log" || fail "the consumer did not see the installed headers"
cmake --build "$work/consumer" -j2 >"$work/build.log" 2>&1 || { cat "$work/build.log"; fail "consumer build"; }
out=$("$work/consumer/seamcl_consumer" "$work/discard.png" paper black)
echo "$out"
[ -s "$work/discard.png" ] || fail "no PNG written"
echo "$out" | grep -q "wrote .*discard.png: paper, discard, 160x120" || fail "unexpected consumer output"
# Black darkens the pixels near every seam that discard renormalises: the two images must differ.
mean=$(echo "$out" | sed -n 's/^black vs discard: mean \([0-9.e+-]*\) .*/\1/p')
[ -n "$mean" ] || fail "no error line"
awk -v m="$mean" 'BEGIN { exit !(m > 0.001 && m < 1) }' || fail "black vs discard mean $mean not in (0.001, 1)"
"$work/consumer/seamcl_consumer" "$work/x.png" paper nosuchmethod 2>"$work/err.txt" && fail "unknown method accepted"
grep -q "SECOND_METHOD: unknown method 'nosuchmethod'" "$work/err.txt" || fail "unknown method message: $(cat "$work/err.txt")"

echo "== consumer through pkg-config"
export PKG_CONFIG_PATH="$libdir/pkgconfig"
pkg-config --exists seamcl || fail "pkg-config does not find seamcl"
[ "$(pkg-config --modversion seamcl)" = "$("$prefix/bin/seamcl" --version | head -1 | awk '{print $2}')" ] || fail "pkg-config version"
# shellcheck disable=SC2046
c++ -std=c++20 -O1 -o "$work/consumer_pc" "$source/examples/consumer/main.cpp" \
  $(pkg-config --cflags seamcl) $(pkg-config --libs --static seamcl) -Wl,-rpath,"$libdir" || fail "pkg-config build"
"$work/consumer_pc" "$work/discard_pc.png" quad2 clamp | grep -q "clamp vs discard: mean" || fail "pkg-config consumer run"
cmp -s "$work/discard.png" "$work/discard_pc.png" && fail "different scenes gave the same PNG"
echo "PASS"

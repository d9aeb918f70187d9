#!/bin/sh
# The programs as installed: `meson install` into a staging root, then the
# installed skybake bakes and the installed skyview renders, both started
# from / so that nothing can be found relative to the build or the source
# tree. The installed files must not name the build or source tree either.
# Usage: test_install.sh MESON BUILD_ROOT SOURCE_ROOT
set -u
meson=$1
build=$2
root=$3
. "$root/tests/cli_lib.sh"
export SKYBAKE_VALIDATE=1

check "meson install into a staging root" expect_exit 0 "$meson" install -C "$build" --destdir "$tmp/root" \
    --no-rebuild --quiet
bin=$(find "$tmp/root" -type f -name skybake -path '*/bin/*' | head -n 1)
check "skybake is installed" test -x "$bin"
bin=$(dirname "$bin")
check "skyview is installed" test -x "$bin/skyview"
# Debug information names the compile directory by design; what the program
# itself can read (everything but the debug sections) must not.
for f in "$bin/skybake" "$bin/skyview"; do
    objcopy --strip-debug "$f" "$tmp/loaded"
    check "$(basename "$f") names neither the build nor the source tree" \
        sh -c "! grep -qaF -e '$build' -e '$root' '$tmp/loaded'"
    check "$(basename "$f") has no run path into the build tree" \
        sh -c "! readelf -d '$f' | grep -qE 'R(UN)?PATH'"
done

# The installed headers are whole: an engine's file that includes them all
# compiles against the staged include folder alone.
inc=$(dirname "$(find "$tmp/root" -type f -name skybake.h -path '*/include/*' | head -n 1)")
for h in "$inc"/*.h; do printf '#include "%s"\n' "$(basename "$h")"; done >"$tmp/headers.c"
printf 'int main(void) { return SB_PACK_FORMAT_VERSION > 0 ? 0 : 1; }\n' >>"$tmp/headers.c"
check "the installed headers compile alone" cc -std=c11 -fsyntax-only $(pkg-config --cflags OpenEXR) -I"$inc" \
    "$tmp/headers.c"

printf '{"version":1,"name":"inst","atmosphere":{"preset":"earth"},"products":["irradiance_ground"]}' >"$tmp/scene.json"
check "the installed skybake bakes from /" sh -c "cd / && '$bin/skybake' bake '$tmp/scene.json' -o '$tmp/pack' -q"
check "the pack has a manifest" test -s "$tmp/pack/manifest.json"
check "the installed skyview renders from / with its built-in defaults" \
    sh -c "cd / && '$bin/skyview' '$tmp/pack' -o '$tmp/frames' --size 64x36 --shadow-size 256 >/dev/null 2>'$tmp/err'"
check "a frame was written" test -s "$tmp/frames/frame_0000.png"

echo "install: $checks checks, $fails failed"
[ "$fails" = 0 ]

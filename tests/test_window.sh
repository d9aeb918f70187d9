#!/bin/sh
# skyview --window under Xvfb with lavapipe: the swapchain's image after N
# frames is the headless frame N, byte for byte (the window copies the
# frame's sRGB bytes into the swapchain; the stated tolerance is 0); the
# timing overlay changes its box and nothing else; validation stays silent;
# and the window's bad combinations are usage errors.
# Usage: test_window.sh SKYVIEW SKYBAKE SOURCE_ROOT
set -u
skyview=$1
skybake=$2
root=$3
. "$root/tests/cli_lib.sh"
export SKYBAKE_VALIDATE=1
stats="python3 $root/tests/png_stats.py"
command -v xvfb-run >/dev/null || { echo "xvfb-run is not installed (apt-get install xvfb xauth)"; exit 1; }
# One X server for the whole test, as xvfb-run starts it.
xvfb() { xvfb-run -a -s "-screen 0 1280x1024x24" "$@"; }

printf '{"version":1,"name":"view","atmosphere":{"preset":"earth"},"products":["irradiance_ground"]}' >"$tmp/view.json"
check "bake the pack" expect_exit 0 "$skybake" bake "$tmp/view.json" -o "$tmp/pack" -q
size="--size 640x360 --shadow-size 256"

check "headless: 5 frames" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/h" $size --frames 5
check "a window under Xvfb: 5 frames, then its swapchain image" \
    expect_exit 0 xvfb "$skyview" "$tmp/pack" -o "$tmp/w" $size --window --frames 5 --no-overlay \
    --screenshot "$tmp/w/shot.png"
check "validation stayed silent (exit 0 with SKYBAKE_VALIDATE=1) and the screenshot was written" \
    test -s "$tmp/w/shot.png"
check "the swapchain's image is the headless frame 5, byte for byte" \
    test "$($stats diff "$tmp/h/frame_0004.png" "$tmp/w/shot.png")" = "0.0000 0"

# The overlay: a shaded box at the top left (about 270 x 270 pixels at this
# size); right of it the frame is untouched.
check "with the overlay" expect_exit 0 xvfb "$skyview" "$tmp/pack" -o "$tmp/o" $size --window --frames 5 \
    --screenshot "$tmp/o/shot.png"
check "right of the overlay's box the frame is the headless one" \
    test "$($stats diff "$tmp/h/frame_0004.png" "$tmp/o/shot.png" 280 0 360 360)" = "0.0000 0"
check "the box is drawn" sh -c "$stats diff '$tmp/h/frame_0004.png' '$tmp/o/shot.png' 0 0 190 260 |
    awk '{ exit !(\$1 > 10) }'"

# The sun from a place and an hour, in the window as headless.
check "headless at 18:30 at 47 N" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/th" $size --frames 3 \
    --time-of-day 18.5 --location 47,8
check "the window at 18:30 at 47 N" expect_exit 0 xvfb "$skyview" "$tmp/pack" -o "$tmp/tw" $size --window \
    --frames 3 --no-overlay --time-of-day 18.5 --location 47,8 --screenshot "$tmp/tw/shot.png"
check "the same frame" test "$($stats diff "$tmp/th/frame_0002.png" "$tmp/tw/shot.png")" = "0.0000 0"

check "--screenshot without --window is a usage error" \
    expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/x" --frames 2 --screenshot "$tmp/x.png"
check "--screenshot without --frames is a usage error" \
    expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/x" --window --screenshot "$tmp/x.png"
check "--window --bench is a usage error" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/x" --window --bench
check "--window with a sweep is a usage error" \
    expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/x" --window --time-of-day 6-8
check "no display: exit 3" expect_exit 3 env -u DISPLAY -u WAYLAND_DISPLAY "$skyview" "$tmp/pack" -o "$tmp/x" \
    --window --frames 1
check "which says so" grep -q "no display" "$tmp/err"

echo "skyview window: $checks checks, $fails failed"
[ "$fails" = 0 ]

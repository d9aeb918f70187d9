#!/bin/sh
# The test level at its small size (data/worlds/village-small.json: 20,000
# triangles of terrain, 3 IFC houses, 20 glTF milk trucks and 40 textured
# boxes scattered on it) baked with every product on this machine's
# device, and drawn by skyview; data/scenes/village.json is the full one.
# Usage: test_level.sh SKYBAKE SKYVIEW SOURCE_ROOT
set -u
skybake=$1
skyview=$2
root=$3
. "$root/tests/cli_lib.sh"
export SKYBAKE_VALIDATE=1

cat >"$tmp/village.json" <<EOF
{"version": 1, "name": "village-small", "atmosphere": {"preset": "earth"},
 "products": ["transmittance", "multiscattering", "irradiance_ground", "irradiance_sky",
              "cloud_shape", "cloud_detail", "cloud_curl", "weather",
              "sky_visibility", "sky_bounce", "dfg", "reflection_cubes", "reflection_probes"],
 "world": {"file": "$root/data/worlds/village-small.json"},
 "clouds": {"cloud_shape": {"size": 32, "worley_cells": [1, 2, 4]}, "cloud_detail": {"size": 16, "worley_cells": [1, 2, 4]}, "cloud_curl": {"size": 32},
            "weather": {"size": 64}},
 "probes": {"spacing_m": 25, "rays": 256, "bounce_rays": 64, "bounce_secondary": 8},
 "reflections": {"face_size": 16, "samples": 32, "ambient_rays": 8,
                 "probes": [{"position_m": [0, 20, 0], "box_m": [[-60, -10, -60], [60, 40, 60]]}]}}
EOF
check "the small level bakes every product" expect_exit 0 "$skybake" bake "$tmp/village.json" -o "$tmp/pack"
check "reading 5 meshes placed 104 times" grep -q "village-small.json: 5 meshes (.*) placed 104 times" "$tmp/err"
check "read once for the probes and the reflections" sh -c "[ \$(grep -c 'placed 104 times' '$tmp/err') -eq 1 ]"
check "every product in the pack" sh -c "[ \$(grep -c '\"content_hash\"' '$tmp/pack/manifest.json') -eq 13 ]"
check "it verifies" expect_exit 0 "$skybake" verify "$tmp/pack"
check "the same bytes again (reusing nothing)" expect_exit 0 "$skybake" bake "$tmp/village.json" -o "$tmp/again" --force -q
check "every content hash the same" sh -c "grep '\"content_hash\"' '$tmp/pack/manifest.json' >'$tmp/a'; grep '\"content_hash\"' '$tmp/again/manifest.json' >'$tmp/b'; cmp -s '$tmp/a' '$tmp/b'"
check "skyview draws it" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/frames" --size 320x180 --camera 0,25,90,0,-12
check "lit by its probes and cubes" sh -c "! grep -q 'another world\\|lit by the sky alone' '$tmp/err'"
check "a frame" test -s "$tmp/frames/frame_0000.png"
echo "level: $checks checks, $fails failed"
echo "$((checks - fails)) passed, $fails failed"
[ "$fails" = 0 ]

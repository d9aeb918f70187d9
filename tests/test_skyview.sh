#!/bin/sh
# skyview as a user runs it: frames and files written, --bench's table and
# JSON, and packs or worlds that must be refused with a message naming what
# is wrong. Usage: test_skyview.sh SKYVIEW SKYBAKE SOURCE_ROOT
set -u
skyview=$1
skybake=$2
root=$3
. "$root/tests/cli_lib.sh"
export SKYBAKE_VALIDATE=1
small="--size 64x36 --shadow-size 256"

# A pack of what skyview reads, and one without multiple scattering.
printf '{"version":1,"name":"view","atmosphere":{"preset":"earth"},"products":["irradiance_ground"]}' >"$tmp/view.json"
printf '{"version":1,"name":"thin","atmosphere":{"preset":"earth"},"products":["transmittance"]}' >"$tmp/thin.json"
check "bake the pack" expect_exit 0 "$skybake" bake "$tmp/view.json" -o "$tmp/pack" -q
check "bake a transmittance-only pack" expect_exit 0 "$skybake" bake "$tmp/thin.json" -o "$tmp/thin" -q

check "help exits 0" expect_exit 0 "$skyview" --help
check "no arguments is a usage error" expect_exit 2 "$skyview"
check "no -o is a usage error" expect_exit 2 "$skyview" "$tmp/pack"
check "bad --size is a usage error" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/f" --size 64by36
check "bad --tonemap is a usage error" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/f" --tonemap reinhard
check "bad --scene is a usage error" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/f" --scene rays

check "one frame" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/f" $small --hdr
check "a pack without the cloud noise has no clouds, and says so" grep -q "clouds: the pack has no cloud_shape.*no clouds" "$tmp/err"
check "frame_0000.png is a PNG" test "$(head -c 8 "$tmp/f/frame_0000.png" | od -An -tx1 | tr -d ' ')" = 89504e470d0a1a0a
check "frame_0000.exr is an EXR" test "$(head -c 4 "$tmp/f/frame_0000.exr" | od -An -tx1 | tr -d ' ')" = 762f3101
# The default world is built in: the same frame from another directory as
# with the world file named.
skyview_abs=$(cd "$(dirname "$skyview")" && pwd)/$(basename "$skyview")
check "from another directory" sh -c "cd / && '$skyview_abs' '$tmp/pack' -o '$tmp/elsewhere' $small >/dev/null 2>&1"
check "with the world file named" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/named" $small --world "$root/data/worlds/test.json"
check "the built-in world is data/worlds/test.json" cmp -s "$tmp/elsewhere/frame_0000.png" "$tmp/named/frame_0000.png"
# A model the default camera cannot see (a box behind it) is framed, and the
# camera reported; the test world and a given --camera are left alone.
# ($tmp/err is the run with the test world named, above)
check "the test world is not framed" sh -c "! grep -q 'framing it' '$tmp/err'"
check "nor lifted" sh -c "! grep -q 'lifted onto it' '$tmp/err'"
# Hills rising over the default camera (3.8 m at the origin, seed 5): it
# stands on them, 1.7 m up, and says so.
printf '{"version":1,"ground":false,"terrain":{"size_m":400,"cells":80,"height_m":20,"seed":5}}' >"$tmp/hills.json"
check "a camera under hills" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/hills" $small --world "$tmp/hills.json"
check "is lifted onto them, and the camera said" grep -q "under the world's surface (at 3.811 m there): lifted onto it, as --camera 0,5.511,0," "$tmp/err"
printf 'v 3 0 27\nv 5 0 27\nv 5 2 27\nv 3 2 27\nv 3 0 33\nv 5 0 33\nv 5 2 33\nv 3 2 33\nf 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n' >"$tmp/behind.obj"
check "a model behind the default camera" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/framed" $small --world "$tmp/behind.obj"
check "is framed, and the camera said" grep -q "the default camera does not show the world (out of its view, or inside a model): framing it, as --camera 4," "$tmp/err"
camera=$(sed -n 's/.*as --camera \([^ ]*\).*/\1/p' "$tmp/err")
check "that camera given" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/given" $small --world "$tmp/behind.obj" --camera "$camera"
check "frames the same" cmp -s "$tmp/framed/frame_0000.png" "$tmp/given/frame_0000.png"
check "and is not framed again" sh -c "! grep -q 'framing it' '$tmp/err'"
# A model around the default camera (a van, 6 m long, the camera in its
# cab): the frame would show its inside; it is framed from outside.
printf 'v -3 0 -1\nv 3 0 -1\nv 3 2.5 -1\nv -3 2.5 -1\nv -3 0 1\nv 3 0 1\nv 3 2.5 1\nv -3 2.5 1\nf 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n' >"$tmp/van.obj"
check "a model around the default camera" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/van" $small --world "$tmp/van.obj"
check "is framed from outside" grep -q "inside a model): framing it, as --camera 0,[0-9.]*,[1-9]" "$tmp/err"
# A level (a world file placing another) draws exactly what the same
# triangles written out in one world file draw.
printf '{"version":1,"ground":false,"boxes":[{"center_m":[0,1,0],"size_m":[2,2,2],"albedo":[0.8,0.3,0.2]}]}' >"$tmp/hut.json"
printf '{"version":1,"instances":[{"file":"hut.json","translate_m":[4,0,-30]},{"file":"hut.json","translate_m":[-6,0,-24]}]}' >"$tmp/level.json"
printf '{"version":1,"boxes":[{"center_m":[4,1,-30],"size_m":[2,2,2],"albedo":[0.8,0.3,0.2]},{"center_m":[-6,1,-24],"size_m":[2,2,2],"albedo":[0.8,0.3,0.2]}]}' >"$tmp/flat.json"
check "a level" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/level" $small --world "$tmp/level.json"
check "its triangles in one world file" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/flat" $small --world "$tmp/flat.json"
check "draw the same frame" cmp -s "$tmp/level/frame_0000.png" "$tmp/flat/frame_0000.png"
check "data/worlds/colonnade.json (docs/fog.md's shafts) loads" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/named" $small --world "$root/data/worlds/colonnade.json"
check "three frames, each tone mapper" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/g" $small --frames 3 --tonemap gt
check "frame_0002.png" test -s "$tmp/g/frame_0002.png"
check "aces" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/g" $small --tonemap aces --no-bloom
# each curve is its own kernel (passes/tonemap.c): the one asked for draws
for t in agx aces gt; do
    check "--tonemap $t" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/tm_$t" $small --tonemap "$t"
done
check "the three tone curves draw three frames" sh -c "! cmp -s '$tmp/tm_agx/frame_0000.png' '$tmp/tm_aces/frame_0000.png' &&
    ! cmp -s '$tmp/tm_agx/frame_0000.png' '$tmp/tm_gt/frame_0000.png' &&
    ! cmp -s '$tmp/tm_aces/frame_0000.png' '$tmp/tm_gt/frame_0000.png'"
check "camera above the atmosphere" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/g" $small --camera 0,1000000,0,0,-60,60
# A camera in a world's valley, 5 m under the planet's ground (the test
# level's terrain goes 12 m under it): the sky as from the ground itself,
# bit for bit, over a world of one box far behind the camera
printf '{"version":1,"ground":false,"boxes":[{"center_m":[0,1,60],"size_m":[2,2,2],"albedo":[0.5,0.5,0.5]}]}' >"$tmp/far_box.json"
check "a camera under y 0" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/valley" $small --world "$tmp/far_box.json" --camera 0,-5,0,0,20,50 --no-fog
check "from the ground" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/ground" $small --world "$tmp/far_box.json" --camera 0,0.01,0,0,20,50 --no-fog
check "sees the same sky" sh -c "test \"\$(python3 '$root/tests/png_stats.py' diff '$tmp/valley/frame_0000.png' '$tmp/ground/frame_0000.png')\" = '0.0000 0'"
check "a camera 10 km under it is refused" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/deep" $small --camera 0,-10001,0
# The traced scene (test_runtime checks its pixels); here the command line.
check "the scene traced" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/t" $small --scene traced --world "$root/data/worlds/colonnade.json"
check "traced, camera above the atmosphere" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/t" $small --scene traced --camera 0,1000000,0,0,-60,60
check "the scene rasterised" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/r" $small --scene raster
if grep -q "on llvmpipe" "$tmp/err"; then
    check "--scene auto rasterises on a CPU device" cmp -s "$tmp/elsewhere/frame_0000.png" "$tmp/r/frame_0000.png"
fi

# Grading through a .cube LUT (test_runtime checks the codes): a neutral
# one leaves the frame as it was; a hostile one is refused, named.
awk 'BEGIN { print "TITLE \"neutral\""; print "LUT_3D_SIZE 33";
    for (b = 0; b < 33; b++) for (g = 0; g < 33; g++) for (r = 0; r < 33; r++) printf "%.6f %.6f %.6f\n", r / 32, g / 32, b / 32 }' >"$tmp/neutral.cube"
check "a neutral grading LUT" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/n" $small --grade "$tmp/neutral.cube"
check "leaves the frame unchanged" cmp -s "$tmp/elsewhere/frame_0000.png" "$tmp/n/frame_0000.png"
printf 'LUT_3D_SIZE 2\n0 0 0\n1 1 1\n' >"$tmp/short.cube"
check "a .cube short of entries is refused" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/n" $small --grade "$tmp/short.cube"
check "naming the file and the count" grep -q "short.cube: 2 entries; LUT_3D_SIZE 2 needs 8" "$tmp/err"
check "a missing .cube is refused" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/n" $small --grade "$tmp/none.cube"
mkfifo "$tmp/fifo.cube" "$tmp/fifo.json"
check "a .cube that is a FIFO is refused at once" expect_exit 2 timeout 60 "$skyview" "$tmp/pack" -o "$tmp/n" $small --grade "$tmp/fifo.cube"
check "--world naming a FIFO is refused at once" expect_exit_not 0 timeout 60 "$skyview" "$tmp/pack" -o "$tmp/n" $small --world "$tmp/fifo.json"
check "naming it" grep -q "fifo.json: not a regular file" "$tmp/err"
# Scene-linear grading and the Purkinje shift (test_post checks the values):
# neutral settings and daylight leave the frame as it was, the others change it.
check "neutral grading settings" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/n" $small --white-balance 6504,0 \
    --saturation 1 --contrast 1 --grade-space srgb
check "leave the frame unchanged" cmp -s "$tmp/elsewhere/frame_0000.png" "$tmp/n/frame_0000.png"
check "graded" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/n" $small --white-balance 3200,5 --saturation 1.2 \
    --contrast 1.1 --grade "$tmp/neutral.cube" --grade-space acescct
check "grading changes the frame" sh -c "! cmp -s '$tmp/elsewhere/frame_0000.png' '$tmp/n/frame_0000.png'"
check "without local tone mapping" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/n" $small --local-contrast 1
check "local tone mapping changes the frame" sh -c "! cmp -s '$tmp/elsewhere/frame_0000.png' '$tmp/n/frame_0000.png'"
check "daylight without the Purkinje shift" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/n" $small --no-purkinje
check "is the same frame" cmp -s "$tmp/elsewhere/frame_0000.png" "$tmp/n/frame_0000.png"
check "dusk with the Purkinje shift" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/n" $small --sun-elevation -8
check "dusk without it" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/n0" $small --sun-elevation -8 --no-purkinje
check "the shift changes dusk" sh -c "! cmp -s '$tmp/n/frame_0000.png' '$tmp/n0/frame_0000.png'"
check "--grade-space acescct without --grade is a usage error" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/x" \
    --grade-space acescct
check "saying so" grep -q "needs --grade" "$tmp/err"
for bad in "--white-balance 900" "--white-balance 5000,60" "--saturation -1" "--contrast 0" "--grade-space log" \
    "--sun-lux 0" "--local-contrast 0.1" "--local-contrast 1.5"; do
    check "$bad is a usage error" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/x" $bad
done

check "bench" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/b" $small --bench --frames 3 --warmup 1 --contrast 1.1
for pass in sky-view probes "aerial perspective" shadows scene sky purkinje exposure "local tonemap" "grade linear" bloom tonemap grade \
    total; do
    check "bench table has $pass" grep -q "^$pass " "$tmp/out"
    check "bench.json has $pass" grep -q "\"pass\":[[:space:]]*\"$pass\"" "$tmp/b/bench.json"
done
for row in "frame as rendered, GPU" "frame as rendered, wall"; do
    check "bench table has $row" grep -q "^$row " "$tmp/out"
    check "bench.json has $row" grep -q "\"pass\":[[:space:]]*\"$row\"" "$tmp/b/bench.json"
done

# A pack with probes over the test world (its atmosphere reused from the
# first pack): skyview draws the world they were baked against and lights
# it with them; --no-probes and another world light it with the sky alone.
cat >"$tmp/probes.json" <<EOF
{"version":1,"name":"view","atmosphere":{"preset":"earth"},"products":["irradiance_ground","sky_visibility"],
 "world":{"file":"$root/data/worlds/test.json"},
 "probes":{"spacing_m":4,"rays":256,"bounds_m":[[-12,0.5,-40],[12,8.5,-8]]}}
EOF
cp -r "$tmp/pack" "$tmp/probes"
check "bake probes into a copy of the pack" expect_exit 0 "$skybake" bake "$tmp/probes.json" -o "$tmp/probes"
check "the atmosphere was reused" grep -q "transmittance.*reused" "$tmp/err"
check "a frame lit by the probes" expect_exit 0 "$skyview" "$tmp/probes" -o "$tmp/p1" $small
check "the probes light the world" grep -q "probes: 7 x 3 x 9.*light the world" "$tmp/err"
check "--no-probes" expect_exit 0 "$skyview" "$tmp/probes" -o "$tmp/p0" $small --no-probes
check "without them, no probe light" sh -c "! grep -q 'light the world' '$tmp/err'"
check "the probes change the frame" sh -c "! cmp -s '$tmp/p1/frame_0000.png' '$tmp/p0/frame_0000.png'"
check "the same world without probes is the first pack's frame" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/p2" $small
check "so the pack's world was the test world" cmp -s "$tmp/p0/frame_0000.png" "$tmp/p2/frame_0000.png"
printf '{"version":1,"boxes":[{"center_m":[0,1,-10],"size_m":[1,1,1]}]}' >"$tmp/other.json"
check "another world" expect_exit 0 "$skyview" "$tmp/probes" -o "$tmp/p3" $small --world "$tmp/other.json"
check "is lit by the sky alone, with a warning" grep -q "baked against another world.*lit by the sky alone" "$tmp/err"

# The cloud noise added to a copy of the pack: skyview draws the clouds
# (with validation on), every bad cloud option is a usage error, and
# --no-clouds gives the pack's frame without them.
cat >"$tmp/clouds.json" <<EOF
{"version":1,"name":"view","atmosphere":{"preset":"earth"},
 "products":["irradiance_ground","cloud_shape","cloud_detail","cloud_curl","weather"],
 "clouds":{"cloud_shape":{"size":64,"worley_cells":[2,4,8]},"weather":{"size":64},"cloud_curl":{"size":32}},
 "cloud_layer":{"coverage":0.6}}
EOF
cp -r "$tmp/pack" "$tmp/clouds"
check "bake the cloud noise into a copy of the pack" expect_exit 0 "$skybake" bake "$tmp/clouds.json" -o "$tmp/clouds" -q
check "a frame with clouds" expect_exit 0 "$skyview" "$tmp/clouds" -o "$tmp/c1" $small --frames 2 --cloud-shadow-size 64
check "the clouds are drawn" grep -q "clouds: 1500 to 4000 m, coverage 0.6" "$tmp/err"
check "--no-clouds" expect_exit 0 "$skyview" "$tmp/clouds" -o "$tmp/c0" $small --frames 2 --no-clouds
check "the clouds change the frame" sh -c "! cmp -s '$tmp/c1/frame_0001.png' '$tmp/c0/frame_0001.png'"
check "lavapipe's settings" expect_exit 0 "$skyview" "$tmp/clouds" -o "$tmp/c2" $small --cloud-scale 4 --cloud-steps 48 \
    --cloud-light-steps 3 --cloud-shadow-size 128
for bad in "--cloud-scale 3" "--cloud-steps 4" "--cloud-light-steps 17" "--cloud-shadow-size 8"; do
    check "$bad is a usage error" expect_exit 2 "$skyview" "$tmp/clouds" -o "$tmp/x" $bad
done
check "bench has the cloud passes" expect_exit 0 "$skyview" "$tmp/clouds" -o "$tmp/cb" $small --bench --frames 2 --warmup 1
for pass in "cloud shadow" clouds; do
    check "bench table has $pass" grep -q "^$pass " "$tmp/out"
done

# Time of day: a sweep's frames, its sequence.json (the sun where the date
# puts it, exposure adapting between frames), the video through ffmpeg (the
# same frames within H.264's loss), a contact sheet, and the bad combinations.
stats="python3 $root/tests/png_stats.py"
sweep="--time-of-day 19.6-20.2 --frames 4 --location 47,8"
check "a sweep into PNGs" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/d1" $small $sweep --encoder png
check "writes frame_0003.png" test -s "$tmp/d1/frame_0003.png"
check "and no video" test ! -e "$tmp/d1/day.mp4"
check "warns that the sun moves too far a frame to keep the history" grep -q "history is dropped.*--frames" "$tmp/err"
check "sequence.json: four frames, the sun on the June solstice at 47 N, exposure adapting" python3 - "$tmp/d1/sequence.json" <<'PY'
import json, math, sys
s = json.load(open(sys.argv[1]))
f = s["frames"]
assert len(f) == 4 and abs(f[0]["hour"] - 19.6) < 1e-12 and abs(f[3]["hour"] - 20.2) < 1e-12, f
# Sunset, so the sun sinks westward and the metered frame darkens.
assert all(a["sun_elevation_deg"] > b["sun_elevation_deg"] for a, b in zip(f, f[1:])), f
assert all(270 < x["sun_azimuth_deg"] < 320 for x in f), f
assert all(a["metered_log2_luminance"] > b["metered_log2_luminance"] for a, b in zip(f, f[1:])), f
# The first frame is a cut (adapted = metered); later the adapted level lags
# above the falling metered one, and moves toward it.
assert f[0]["adapted_log2_luminance"] == f[0]["metered_log2_luminance"], f[0]
for a, b in zip(f, f[1:]):
    assert b["metered_log2_luminance"] < b["adapted_log2_luminance"] < a["adapted_log2_luminance"], (a, b)
PY
check "a sweep without --frames takes enough frames for the history" \
    expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/d2" $small --time-of-day 12-12.1 --location 47,8 --encoder png
check "and does not warn" sh -c "! grep -q 'history is dropped' '$tmp/err'"
check "9 frames (13.8 degrees an hour, 0.19 a frame), noon at 66.4 degrees" python3 - "$tmp/d2/sequence.json" <<'PY'
import json, sys
f = json.load(open(sys.argv[1]))["frames"]
assert len(f) == 9, len(f)
assert abs(f[0]["sun_elevation_deg"] - (90 - 47 + 23.436)) < 0.05, f[0]
PY
check "one hour renders one sun" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/d3" $small --time-of-day 19.6 --location 47,8
check "the sweep's first frame is that hour's" cmp -s "$tmp/d1/frame_0000.png" "$tmp/d3/frame_0000.png"

check "a sweep through ffmpeg" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/v1" $small $sweep --encoder ffmpeg
check "writes day.mp4 and no PNG" sh -c "test -s '$tmp/v1/day.mp4' && ! test -e '$tmp/v1/frame_0000.png'"
check "the video is 4 frames of 64 x 36 H.264" test "$(ffprobe -v error -select_streams v:0 -count_frames \
    -show_entries stream=codec_name,width,height,nb_read_frames -of csv=p=0 "$tmp/v1/day.mp4")" = "h264,64,36,4"
ffmpeg -v error -i "$tmp/v1/day.mp4" -vf "select=eq(n\,3)" -frames:v 1 "$tmp/v1/decoded.png" </dev/null
# H.264 at CRF 18 with 4:2:0 chroma: at 64 x 36 each frame decodes 2.7 to
# 3.0 codes from its PNG on average, at most 51 (at the coloured boxes'
# edges: a chroma sample spans 2 x 2 pixels of a tiny frame; 1.7 at
# 320 x 180). Neighbouring frames of this sweep differ by 26 to 88, so the
# bound tells the right frame (decoded as the Rec.709 it is tagged) apart.
check "its last frame is the PNG sweep's within H.264's loss (mean < 4, max < 64 codes)" \
    sh -c "$stats diff '$tmp/d1/frame_0003.png' '$tmp/v1/decoded.png' | tee '$tmp/v1/diff' |
           awk '{ exit !(\$1 < 4 && \$2 < 64) }'"
echo "video against PNG: $(cat "$tmp/v1/diff")"
check "auto encodes with ffmpeg when it is on PATH" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/v2" $small $sweep
check "(day.mp4)" test -s "$tmp/v2/day.mp4"
check "auto without ffmpeg on PATH writes PNGs" \
    expect_exit 0 env PATH=/nonexistent "$skyview" "$tmp/pack" -o "$tmp/v3" $small $sweep
check "(frame_0003.png, and says why)" sh -c "test -s '$tmp/v3/frame_0003.png' && grep -q 'no ffmpeg on PATH' '$tmp/err'"
check "--encoder ffmpeg without ffmpeg is a usage error" \
    expect_exit 2 env PATH=/nonexistent "$skyview" "$tmp/pack" -o "$tmp/x" $small $sweep --encoder ffmpeg
check "that names the package" grep -q "apt-get install ffmpeg" "$tmp/err"
check "ffmpeg left no partial file" sh -c "! ls '$tmp/v1' '$tmp/v2' | grep -q partial"

check "a contact sheet" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/s1" $small --time-of-day 6-18 \
    --contact-sheet 6 --location 47,8
check "3 frames of 64 x 36 in a 2 x 2 grid with label strips: 134 x 100" \
    test "$($stats size "$tmp/s1/contact_sheet.png")" = "134 100"
check "a label under the first frame" test "$($stats ink "$tmp/s1/contact_sheet.png" 2 38 64 11 24 24 24)" -gt 20
check "the fourth cell empty" test "$($stats ink "$tmp/s1/contact_sheet.png" 68 51 64 47 24 24 24)" = 0

# The moon: by the date at night (the full moon of 2026-06-29, 13.5
# degrees up in the south-south-east at 23 h at 47 N, 8 E), lighting a
# frame that without it is the range's black; by hand; and the bad
# combinations.
night="--time-of-day 23-23.01 --frames 2 --location 47,8 --date 2026-06-29 --encoder png"
check "a moonlit night" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/m1" $small $night
check "sequence.json places the moon (a sweep writes it)" python3 - "$tmp/m1/sequence.json" <<'PY'
import json, sys
f = json.load(open(sys.argv[1]))["frames"][0]
assert abs(f["moon_elevation_deg"] - 13.5) < 0.2 and abs(f["moon_azimuth_deg"] - 165.9) < 0.3, f
assert f["sun_elevation_deg"] < -18, f
PY
check "the same night without the moon" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/m2" $small $night --no-moon
check "is darker: the moon lights the frame" python3 - "$tmp/m1/frame_0000.png" "$tmp/m2/frame_0000.png" <<PY
import subprocess, sys
mean = lambda p: sum(map(float, subprocess.check_output(["python3", "$root/tests/png_stats.py", "mean", p]).split()))
lit, dark = mean(sys.argv[1]), mean(sys.argv[2])
assert lit > 30 and lit > 4 * dark, (lit, dark)
PY
check "a moon by hand" expect_exit 0 "$skyview" "$tmp/pack" -o "$tmp/m3" $small --sun-elevation -30 --moon 20,150 \
    --ev-range -6,16 --dim-compensation 0.5

for bad in "--time-of-day 8-6" "--time-of-day 49" "--time-of-day 6-" "--time-of-day 12 --sun-elevation 10" \
           "--moon 10" "--moon 95,0" "--moon 10,0 --no-moon" "--time-of-day 22 --moon 10,0" "--ev-range 5,2" \
           "--ev-range -30,10" "--dim-compensation 2" \
           "--location 47,8" "--time-of-day 6-8 --location 91,0" "--time-of-day 6-8 --date 2026-02-30" \
           "--time-of-day 6-8 --sun-keys 6:0:90" "--time-of-day 6-8 --sun-keys 6:0:90,7:5:100 --date 2026-01-01" \
           "--time-of-day 6-8 --frames 1" "--time-of-day 6-8 --bench" "--time-of-day 6 --encoder png" \
           "--time-of-day 6-8 --encoder mkv" "--time-of-day 6.1-6.9 --contact-sheet 1" \
           "--time-of-day 6-8 --contact-sheet 1 --frames 3" "--time-of-day 6-8 --fps 0" \
           "--time-of-day 0-48 --contact-sheet 0.5"; do
    check "$bad is a usage error" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/x" $small $bad
done
check "a bad key's message names it" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/x" --time-of-day 6-8 \
    --sun-keys 6:0:90,5:5:100
check "(key 2's hour)" grep -q "key 2's hour 5 does not follow" "$tmp/err"

# Packs that must be refused, with what is wrong named.
cp -r "$tmp/pack" "$tmp/edited"
sed -i '0,/"content_hash":[[:space:]]*"[0-9a-f]*"/s//"content_hash": "00000000000000000000000000000000"/' \
    "$tmp/edited/manifest.json"
check "a recorded hash that differs is refused" expect_exit 2 "$skyview" "$tmp/edited" -o "$tmp/x"
check "the message says hash" grep -q "hash" "$tmp/err"
check "nothing was written" test ! -e "$tmp/x"
cp -r "$tmp/pack" "$tmp/missing"
rm "$tmp/missing/irradiance_ground.exr"
check "a missing artifact is refused" expect_exit 2 "$skyview" "$tmp/missing" -o "$tmp/x"
check "the message names the file" grep -q "irradiance_ground.exr" "$tmp/err"
cp -r "$tmp/pack" "$tmp/future"
next=$(($(sed -n 's/.*"format_version":[[:space:]]*\([0-9]*\).*/\1/p' "$tmp/pack/manifest.json") + 1))
sed -i "s/\"format_version\":[[:space:]]*[0-9]*/\"format_version\": $next/" "$tmp/future/manifest.json"
check "an unknown format version is refused" expect_exit 2 "$skyview" "$tmp/future" -o "$tmp/x"
check "the message says rebake" grep -q "rebake needed" "$tmp/err"
# an orders table baked on another grid (the same shape): refused, not read between the wrong nodes
printf '{"version":1,"name":"orders","atmosphere":{"preset":"earth"},"products":["orders"]}' >"$tmp/orders.json"
check "bake a pack with the orders" expect_exit 0 "$skybake" bake "$tmp/orders.json" -o "$tmp/grid" -q
check "which skyview reads" expect_exit 0 "$skyview" "$tmp/grid" -o "$tmp/grid-frame" $small
sed -i 's/"top_km":[[:space:]]*[0-9.e+]*/"top_km": 12720/' "$tmp/grid/manifest.json"
check "the orders' grid is recorded" grep -q '"top_km": 12720' "$tmp/grid/manifest.json"
check "an orders table of another grid is refused" expect_exit 2 "$skyview" "$tmp/grid" -o "$tmp/x"
check "the message names the field and says rebake" grep -q "orders.exr: baked on a grid .*settings.top_km.*rebake needed" "$tmp/err"
check "nothing was written" test ! -e "$tmp/x"
check "a pack without multiscattering is refused" expect_exit 2 "$skyview" "$tmp/thin" -o "$tmp/x"
check "the message names multiscattering" grep -q "multiscattering" "$tmp/err"
check "a directory that is not a pack is refused" expect_exit 2 "$skyview" "$tmp" -o "$tmp/x"

printf '{"version":1,"boxes":[{"center_m":[0,1,0],"size_m":[1,1,1],"colour":[1,0,0]}]}' >"$tmp/world.json"
check "a world with an unknown key is refused" expect_exit 2 "$skyview" "$tmp/pack" -o "$tmp/x" --world "$tmp/world.json"
check "the message names the key" grep -q "boxes\[0\].colour" "$tmp/err"
check "output into a missing parent fails" expect_exit 1 "$skyview" "$tmp/pack" -o "$tmp/missing/parent/f" $small

echo "skyview cli: $checks checks, $fails failed"
[ "$fails" = 0 ]

#!/bin/sh
# Sky-visibility probes as a user bakes them: a scene with a world, the
# bake graph (the atmosphere does not rebake probes; a vertex does), verify,
# info and diff, and bad worlds refused with the file named and the old
# pack left whole. Usage: test_probes_cli.sh SKYBAKE SOURCE_ROOT
set -u
skybake=$1
root=$2
. "$root/tests/cli_lib.sh"
export SKYBAKE_VALIDATE=1

# A small world: a ground, a table-like slab on four legs, a closed box.
cat >"$tmp/world.obj" <<'OBJ'
v -10 0 -10
v -10 0 10
v 10 0 10
v 10 0 -10
f 1 2 3
f 1 3 4
v -2 2 -2
v 2 2 -2
v 2 2 2
v -2 2 2
f 5 6 7
f 5 7 8
f 5 8 7
f 5 7 6
OBJ
scene() { # products-json atmosphere-json extra
    printf '{"version":1,"name":"probes","atmosphere":%s,"products":%s,"world":{"file":"world.obj"},"probes":{"spacing_m":4,"rays":512%s}}' "$2" "$1" "$3"
}
scene '["sky_visibility"]' '{"preset":"earth"}' '' >"$tmp/s.json"
scene '["sky_visibility"]' '{"preset":"earth","mie_g":0.7}' '' >"$tmp/s_g.json"
check "bake probes" expect_exit 0 "$skybake" bake "$tmp/s.json" -o "$tmp/p" --json -q
check "the pack holds the probe file" test -s "$tmp/p/sky_visibility.sbprobes"
check "only what was asked for" test ! -e "$tmp/p/transmittance.exr"
check "verify" expect_exit 0 "$skybake" verify "$tmp/p"
check "info lists sky_visibility" expect_exit 0 "$skybake" info "$tmp/p"
check "info shows the grid" grep -q '"grid":\[6,1,6\]' "$tmp/out"
check "manifest has format_version 15" grep -Eq '"format_version":[[:space:]]*15,' "$tmp/p/manifest.json"
check "diff with itself" expect_exit 0 "$skybake" diff "$tmp/p" "$tmp/p"
hash() { sed -n 's/.*"content_hash":[[:space:]]*"\([0-9a-f]*\)".*/\1/p' "$tmp/p/manifest.json"; }
first=$(hash)
check "a rebake reuses the probes" expect_exit 0 "$skybake" bake "$tmp/s.json" -o "$tmp/p"
check "reused (key unchanged)" grep -q "sky_visibility.*reused" "$tmp/err"
check "another atmosphere: the probes are reused" expect_exit 0 "$skybake" bake "$tmp/s_g.json" -o "$tmp/p"
check "reused after an atmosphere change" grep -q "sky_visibility.*reused" "$tmp/err"
check "the same probes" test "$(hash)" = "$first"
sed -i 's/^v 2 2 2$/v 2 2.5 2/' "$tmp/world.obj"
check "a vertex moved: rebaked" expect_exit 0 "$skybake" bake "$tmp/s.json" -o "$tmp/p"
check "not reused after a vertex moved" sh -c "! grep -q 'sky_visibility.*reused' '$tmp/err'"
check "other probes" test "$(hash)" != "$first"
check "forced rebake, same bytes" expect_exit 0 "$skybake" bake "$tmp/s.json" -o "$tmp/q" --force -q
check "deterministic" cmp -s "$tmp/p/sky_visibility.sbprobes" "$tmp/q/sky_visibility.sbprobes"

# On a terminal the steps show what they are doing (script(1) gives the
# bake one); not on a file, nor with -q.
check "a bake on a terminal" sh -c "script -qec \"'$skybake' bake '$tmp/s.json' -o '$tmp/tty' --force\" /dev/null >'$tmp/tty.txt'"
check "shows the world loading" grep -q "loading world.obj" "$tmp/tty.txt"
check "shows the BVH" grep -q "BVH: 6 triangles on" "$tmp/tty.txt"
check "shows the product" grep -q "sky_visibility (1 of 1 products)" "$tmp/tty.txt"
check "shows the writing" grep -q "writing the pack" "$tmp/tty.txt"
check "a quiet bake on a terminal" sh -c "script -qec \"'$skybake' bake '$tmp/s.json' -o '$tmp/tty' --force -q\" /dev/null >'$tmp/tty.txt'"
check "shows none of it" sh -c "! grep -q 'BVH:\\|loading\\|products)' '$tmp/tty.txt'"
check "a bake into a file" expect_exit 0 "$skybake" bake "$tmp/s.json" -o "$tmp/tty" --force
check "writes none of it" sh -c "! grep -q 'BVH:\\|loading\\|products)' '$tmp/err'"

# The thread count changes no byte: a world of 80,000 triangles (a bumpy
# grid, more than one thread's share of the BVH build) baked on 1 and on
# 3 threads gives the same probe files.
awk 'BEGIN { n = 201; for (j = 0; j < n; j++) for (i = 0; i < n; i++)
                 printf "v %d %.4f %d\n", i - 100, 0.5 * sin(i * 0.7) * cos(j * 0.45), j - 100;
             for (j = 0; j + 1 < n; j++) for (i = 0; i + 1 < n; i++) { a = j * n + i + 1;
                 printf "f %d %d %d\nf %d %d %d\n", a, a + n, a + 1, a + 1, a + n, a + n + 1 } }' >"$tmp/grid.obj"
printf '{"version":1,"name":"grid","atmosphere":{"preset":"earth"},"products":["sky_visibility","sky_bounce"],"world":{"file":"grid.obj"},"probes":{"spacing_m":50,"rays":256,"bounce_rays":64,"bounce_secondary":8}}' >"$tmp/grid.json"
check "bake the grid on 1 thread" expect_exit 0 "$skybake" bake "$tmp/grid.json" -o "$tmp/t1" --threads 1 -q
check "bake the grid on 3 threads" expect_exit 0 "$skybake" bake "$tmp/grid.json" -o "$tmp/t3" --threads 3 -q
check "the same visibility on 1 and 3 threads" cmp -s "$tmp/t1/sky_visibility.sbprobes" "$tmp/t3/sky_visibility.sbprobes"
check "the same bounce on 1 and 3 threads" cmp -s "$tmp/t1/sky_bounce.sbprobes" "$tmp/t3/sky_bounce.sbprobes"
# A level: the grid placed twice, a world file of a cube placed in turn,
# and 30 cubes scattered over the grid; on 1 and 3 threads, the same files.
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n' >"$tmp/cube.obj"
printf '{"version":1,"ground":false,"boxes":[{"center_m":[0,2,0],"size_m":[4,4,4]}],"instances":[{"file":"cube.obj","translate_m":[3,0,0]}]}' >"$tmp/hut.json"
printf '{"version":1,"ground":false,"instances":[{"file":"grid.obj"},{"file":"grid.obj","translate_m":[200,0,0],"rotate_deg":[0,90,0]},{"file":"hut.json","translate_m":[10,0.5,10]},{"file":"hut.json","translate_m":[-20,0.5,5],"scale":1.5}],"scatter":[{"file":"cube.obj","count":30,"seed":5,"area_m":[-90,-90,90,90],"scale":[1,3]}]}' >"$tmp/village.json"
printf '{"version":1,"name":"village","atmosphere":{"preset":"earth"},"products":["sky_visibility","sky_bounce"],"world":{"file":"village.json"},"probes":{"spacing_m":40,"rays":256,"bounce_rays":64,"bounce_secondary":8}}' >"$tmp/village-scene.json"
check "bake a level on 1 thread" expect_exit 0 "$skybake" bake "$tmp/village-scene.json" -o "$tmp/v1" --threads 1
# the grid, the hut's box, the cube: 80,024 triangles, placed 2 + 2 x 2 + 30 times
check "it says what it placed" grep -q "village.json: 3 meshes (80024 triangles) placed 36 times: 160408 triangles" "$tmp/err"
check "bake it on 3 threads" expect_exit 0 "$skybake" bake "$tmp/village-scene.json" -o "$tmp/v3" --threads 3 -q
check "the same visibility on 1 and 3 threads" cmp -s "$tmp/v1/sky_visibility.sbprobes" "$tmp/v3/sky_visibility.sbprobes"
check "the same bounce on 1 and 3 threads" cmp -s "$tmp/v1/sky_bounce.sbprobes" "$tmp/v3/sky_bounce.sbprobes"
check "the manifest counts the placed triangles" grep -q '"triangles":[[:space:]]*160408' "$tmp/v1/manifest.json"
printf '{"version":1,"instances":[{"file":"nowhere.obj"}]}' >"$tmp/broken.json"
printf '{"version":1,"name":"broken","atmosphere":{"preset":"earth"},"products":["sky_visibility"],"world":{"file":"broken.json"}}' >"$tmp/broken-scene.json"
check "a level placing a missing file is refused" expect_exit 1 "$skybake" bake "$tmp/broken-scene.json" -o "$tmp/vb"
check "naming the world file, the field and the file" grep -q "broken.json: instances: cannot read .*nowhere.obj" "$tmp/err"
check "and nothing was written" test ! -e "$tmp/vb"
check "--threads 0 is refused" expect_exit 2 "$skybake" bake "$tmp/grid.json" -o "$tmp/t0" --threads 0
check "naming the option" grep -q -- "--threads: '0'" "$tmp/err"
check "not as an unknown option" sh -c "! grep -q 'unknown or incomplete' '$tmp/err'"
check "and nothing was written" test ! -e "$tmp/t0"

# The bounce: a product of its own over the same probes. Asking for it
# reuses the visibility; its own settings rebake it alone.
scene '["sky_visibility","sky_bounce"]' '{"preset":"earth"}' ',"bounce_rays":128,"bounce_secondary":16' >"$tmp/b.json"
check "bake the bounce" expect_exit 0 "$skybake" bake "$tmp/b.json" -o "$tmp/p"
check "the visibility is reused" grep -q "sky_visibility.*reused" "$tmp/err"
check "the pack holds the bounce" test -s "$tmp/p/sky_bounce.sbprobes"
check "info lists sky_bounce" expect_exit 0 "$skybake" info "$tmp/p" --json
check "108 channels" grep -q '"channels":[[:space:]]*"bounce.0.0.r,.*bounce.3.8.b"' "$tmp/out"
sed -i 's/"bounce_secondary":16/"bounce_secondary":24/' "$tmp/b.json"
check "other bounce settings" expect_exit 0 "$skybake" bake "$tmp/b.json" -o "$tmp/p"
check "rebake the bounce alone" sh -c "grep -q 'sky_visibility.*reused' '$tmp/err' && ! grep -q 'sky_bounce.*reused' '$tmp/err'"
check "every bounce by default, saying what the later ones added" sh -c "tr -d '[:space:]' <'$tmp/p/manifest.json' | grep -q '\"bounces\":0,\"bounces_summed\":[0-9]*,\"added_mean\":[0-9.e-]*,'"
sed -i 's/"bounce_secondary":24/"bounce_secondary":24,"bounces":1/' "$tmp/b.json"
check "one bounce" expect_exit 0 "$skybake" bake "$tmp/b.json" -o "$tmp/p"
check "rebakes the bounce alone" sh -c "grep -q 'sky_visibility.*reused' '$tmp/err' && ! grep -q 'sky_bounce.*reused' '$tmp/err'"
check "its settings say one" sh -c "tr -d '[:space:]' <'$tmp/p/manifest.json' | grep -q '\"bounces\":1,\"bounces_summed\":1,\"added_mean\":0,'"
check "the bounce alone asks for the visibility" sh -c "printf '{\"atmosphere\":{\"preset\":\"earth\"},\"products\":[\"sky_bounce\"],\"world\":{\"file\":\"world.obj\"},\"probes\":{\"spacing_m\":4,\"rays\":64,\"bounce_rays\":64,\"bounce_secondary\":8}}' >'$tmp/bo.json' && '$skybake' bake '$tmp/bo.json' -o '$tmp/bo' -q && test -s '$tmp/bo/sky_visibility.sbprobes'"
check "the bounce's settings only in scenes that ask for it" sh -c "grep -q bounce_rays '$tmp/bo/manifest.json' && ! grep -q bounce_rays '$tmp/q/manifest.json'"

# The key is the world as read, not the scene's file name: a world reached
# through a symbolic link rebakes when the file it points to changes.
cp "$tmp/world.obj" "$tmp/real.obj"
ln -s real.obj "$tmp/linked.obj"
scene '["sky_visibility"]' '{"preset":"earth"}' '' | sed 's/world.obj/linked.obj/' >"$tmp/linked.json"
check "bake a linked world" expect_exit 0 "$skybake" bake "$tmp/linked.json" -o "$tmp/l"
sed -i 's/^v 2 2.5 2$/v 2 3 2/' "$tmp/real.obj"
check "rebake after the linked file changed" expect_exit 0 "$skybake" bake "$tmp/linked.json" -o "$tmp/l"
check "not reused after the linked file changed" sh -c "! grep -q 'sky_visibility.*reused' '$tmp/err'"

# Bad worlds: named, exit 1 at bake (2 for the scene), the old pack whole.
cp -r "$tmp/p" "$tmp/before"
scene '["sky_visibility"]' '{"preset":"earth"}' '' | sed 's/world.obj/missing.obj/' >"$tmp/missing.json"
check "a missing world file is a failed bake" expect_exit 1 "$skybake" bake "$tmp/missing.json" -o "$tmp/p"
check "it names the file" grep -q "missing.obj" "$tmp/err"
printf 'not a mesh at all' >"$tmp/garbage.obj"
scene '["sky_visibility"]' '{"preset":"earth"}' '' | sed 's/world.obj/garbage.obj/' >"$tmp/garbage.json"
check "a file assimp refuses is a failed bake" expect_exit 1 "$skybake" bake "$tmp/garbage.json" -o "$tmp/p"
check "it names that file" grep -q "garbage.obj" "$tmp/err"
check "the old pack is whole" diff -r "$tmp/p" "$tmp/before"
printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility"]}' >"$tmp/noworld.json"
check "sky_visibility without a world is a scene error" expect_exit 2 "$skybake" bake "$tmp/noworld.json" -o "$tmp/n"
check "it says what is missing" grep -q "needs a \"world\"" "$tmp/err"
for bad in '"bounce_rays":100' '"bounce_secondary":3' '"bounces":65' '"bounces":-1' '"bounces":1.5' '"bounds_m":[[0,0,0],[1,1]]' '"bounds_m":[[0,0,0],[1,-1,1]]' '"bounds_m":[[0,0,0],[1,1,2e4]]' \
    '"spacing_m":-1' '"rays":100' '"rays":1e9' '"inside_fraction":2' '"positions_m":[[1,2]]' '"nope":1' '"spacing_m":0'; do
    printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility"],"world":{"file":"world.obj"},"probes":{%s}}' "$bad" >"$tmp/bad.json"
    check "probes {$bad} is a scene error" expect_exit 2 "$skybake" bake "$tmp/bad.json" -o "$tmp/n"
    check "it names probes" grep -q "probes" "$tmp/err"
done
scene '["sky_visibility"]' '{"preset":"earth"}' '' | sed 's/"spacing_m":4/"spacing_m":0.01/' >"$tmp/dense.json"
check "a grid past the caps is refused" expect_exit 1 "$skybake" bake "$tmp/dense.json" -o "$tmp/n"
check "it says to raise the spacing" grep -q "raise probes.spacing_m" "$tmp/err"
# Found from the scene and its world, before any product is baked (it was
# found after the atmosphere's bakes).
scene '["transmittance","sky_visibility"]' '{"preset":"earth"}' '' | sed 's/"spacing_m":4/"spacing_m":0.01/' >"$tmp/dense2.json"
check "a grid past the caps, beside the atmosphere" expect_exit 1 "$skybake" bake "$tmp/dense2.json" -o "$tmp/n"
check "is refused before any product is baked" sh -c "! grep -q '^transmittance' '$tmp/err'"
# A world file whose box lies beyond 10 km: refused, naming the file, and
# (under LeakSanitizer) nothing of the half-built mesh leaks.
printf '{"version":1,"boxes":[{"center_m":[9999,0,0],"size_m":[10,1,1]}]}' >"$tmp/far.json"
printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility"],"world":{"file":"far.json"},"probes":{"spacing_m":4}}' >"$tmp/farscene.json"
check "a world beyond 10 km is refused" expect_exit 1 "$skybake" bake "$tmp/farscene.json" -o "$tmp/n"
check "naming the world file" grep -q "far.json: .*10000 m" "$tmp/err"
check "the tolerance is refused for probes" sh -c "printf '{\"atmosphere\":{\"preset\":\"earth\"},\"products\":[\"sky_visibility\"],\"world\":{\"file\":\"w.obj\"},\"tolerance\":{\"sky_visibility\":0.01}}' >'$tmp/tol.json'; '$skybake' bake '$tmp/tol.json' -o '$tmp/n' 2>/dev/null; test \$? = 2"

# The grid over given bounds instead of the world's casters (the test
# world's boxes and pillars span 100 m: too wide for a grid 5 cm apart; its
# 20 km ground is no caster), a skybake world file as the world.
cat >"$tmp/outdoor.json" <<EOF
{"version":1,"atmosphere":{"preset":"earth"},"products":["sky_visibility"],
 "world":{"file":"$root/data/worlds/test.json"},"probes":{"spacing_m":0.05,"rays":256}}
EOF
check "the test world's casters 5 cm apart need probes.bounds_m" expect_exit 1 "$skybake" bake "$tmp/outdoor.json" -o "$tmp/o"
check "it says to give bounds" grep -q "give probes.bounds_m" "$tmp/err"
check "it names the casters' width along z, not the ground's" grep -q "probes along z (the world is 10[0-9].[0-9] m across" "$tmp/err"
check "and a model's units" grep -q "set world.units_m" "$tmp/err"
scene '["sky_visibility"]' '{"preset":"earth"}' '' | sed 's/"spacing_m":4/"spacing_m":0.05/' >"$tmp/dense.json"
check "too many probes in all" expect_exit 1 "$skybake" bake "$tmp/dense.json" -o "$tmp/n"
check "names the grid and what to change" grep -q "a grid of 401 x [0-9]* x 401, 0.05 m apart, over the world's shadow casters); at most 1048576: raise probes.spacing_m, give probes.bounds_m, or, for a model in millimetres or centimetres, set world.units_m" "$tmp/err"
sed -i 's/"spacing_m":0.05,"rays":256/"spacing_m":4,"rays":256,"bounds_m":[[-8,0.5,-30],[8,8.5,-14]]/' "$tmp/outdoor.json"
check "a grid over the scene's bounds" expect_exit 0 "$skybake" bake "$tmp/outdoor.json" -o "$tmp/o"
check "5 x 3 x 5 probes" expect_exit 0 "$skybake" info "$tmp/o"
check "info shows that grid" grep -q '"grid":\[5,3,5\]' "$tmp/out"
check "the world's hash and path are recorded" grep -Eq "baked against the world .*data/worlds/test.json \([0-9a-f]{32}\)" "$tmp/out"
check "in the manifest's own fields" grep -q '"world_path":[[:space:]]*".*data/worlds/test.json"' "$tmp/o/manifest.json"

# A probe file edited in the pack: verify names it.
cp -r "$tmp/p" "$tmp/edited"
printf '\001' | dd of="$tmp/edited/sky_visibility.sbprobes" bs=1 seek=200 conv=notrunc 2>/dev/null
check "verify refuses an edited probe file" expect_exit 1 "$skybake" verify "$tmp/edited"
check "naming it" grep -q "sky_visibility" "$tmp/err"

# Reflection probes over the test world: the cubes open in OpenEXR's own
# tools as a mip-mapped cube-face map; a probe inside geometry is refused
# naming it, and nothing is written.
refl() { # probes-json
    printf '{"version":1,"name":"refl","atmosphere":{"preset":"earth"},"products":["reflection_probes"],"world":{"file":"%s"},"reflections":{"face_size":16,"samples":64,"ambient_rays":8,"probes":%s}}' \
        "$root/data/worlds/test.json" "$1"
}
refl '[{"position_m":[0,1.5,-20],"box_m":[[-12,0,-40],[12,10,-8]]}]' >"$tmp/r.json"
check "bake reflection probes" expect_exit 0 "$skybake" bake "$tmp/r.json" -o "$tmp/r"
check "the cubes are in the pack" test -s "$tmp/r/reflection_cubes.exr"
check "and the probes' records" test -s "$tmp/r/reflection_probes.sbprobes"
check "verify the reflection pack" expect_exit 0 "$skybake" verify "$tmp/r"
if command -v exrheader >/dev/null; then
    check "exrheader reads the cubes" expect_exit 0 exrheader "$tmp/r/reflection_cubes.exr"
    check "as cube-face maps" grep -q "envmap (type envmap): cube-face map" "$tmp/out"
    check "mip-mapped" grep -q "mip-map" "$tmp/out"
    check "two parts: the sky's probe and the scene's" grep -q "part 1:" "$tmp/out"
fi
check "a contact sheet of the cubes" expect_exit 0 "$skybake" preview "$tmp/r" "$tmp/sheet.png"
check "is a PNG" sh -c "head -c 8 '$tmp/sheet.png' | od -An -c | grep -q 'P   N   G'"
check "a pack of probes without cubes previews their layout" expect_exit 0 "$skybake" preview "$tmp/p" "$tmp/layout.png"
check "as a PNG" sh -c "head -c 8 '$tmp/layout.png' | od -An -c | grep -q 'P   N   G'"
refl '[{"position_m":[0,0.5,-18],"box_m":[[-12,0,-40],[12,10,-8]]}]' >"$tmp/r_inside.json"
check "a probe inside the metal box is refused" expect_exit 1 "$skybake" bake "$tmp/r_inside.json" -o "$tmp/r_inside"
check "naming it" grep -q "reflections.probes\[0\].*inside geometry" "$tmp/err"
check "and nothing is written" test ! -e "$tmp/r_inside"
refl '[{"position_m":[0,1,0],"box_m":[[0,0,0],[0,3,5]]}]' >"$tmp/r_flat.json"
check "a flat box is refused" expect_exit 2 "$skybake" bake "$tmp/r_flat.json" -o "$tmp/r_flat"
check "naming the field" grep -q "reflections.probes\[0\].box_m" "$tmp/err"

# A grid of layers that follows the surface: spacing 3 m over the world's
# 20 m, so that the middle column stands over the slab (2 m up) and the
# others over the ground; each probe at its layer's height over its column.
sed -i 's/^v 2 2.5 2$/v 2 2 2/' "$tmp/world.obj"
printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility","sky_bounce"],"world":{"file":"world.obj"},"probes":{"spacing_m":3,"rays":512,"layers_m":[1,5],"bounce_rays":64,"bounce_secondary":8}}' >"$tmp/layers.json"
check "bake a grid of layers" expect_exit 0 "$skybake" bake "$tmp/layers.json" -o "$tmp/layers" -q
check "verify it" expect_exit 0 "$skybake" verify "$tmp/layers"
check "info gives the grid and its layers" expect_exit 0 "$skybake" info "$tmp/layers"
check "7 columns by 7, 2 layers" grep -q '"grid":\[7,2,7\].*"layers_m":\[1,5\]' "$tmp/out"
check "each probe at its layer over the surface under its column" python3 - "$tmp/layers/sky_visibility.sbprobes" <<'PY'
import struct, sys
b = open(sys.argv[1], "rb").read()
version, = struct.unpack_from("<I", b, 8)
header, channels, count = struct.unpack_from("<III", b, 16)
nx, nl, nz = struct.unpack_from("<III", b, 28)
layers, = struct.unpack_from("<I", b, 104)
heights = struct.unpack_from("<%df" % layers, b, 108)
assert version == 2 and header == 152 and layers == nl == 2 and heights == (1.0, 5.0), (version, header, layers, heights)
for z in range(nz):
    for x in range(nx):
        want = 2.0 if x == nx // 2 and z == nz // 2 else 0.0  # the slab under the middle column
        for l in range(nl):
            r = struct.unpack_from("<%df" % channels, b, header + 4 * channels * (x + nx * (l + nl * z)))
            surface = r[1] - r[4] - heights[l]  # where it was placed, before any push out
            assert abs(surface - want) < 1e-4, (x, l, z, surface, want)
            assert abs(r[0] - r[3] - (-9 + 3 * x)) < 1e-5 and abs(r[2] - r[5] - (-9 + 3 * z)) < 1e-5, (x, z, r[:6])
PY
cp -r "$tmp/layers" "$tmp/layers6"
sed -i 's/"format_version":[[:space:]]*[0-9]*/"format_version": 6/' "$tmp/layers6/manifest.json"
check "a grid in layers in a version 6 pack is refused" expect_exit 1 "$skybake" verify "$tmp/layers6"
check "naming the version" grep -q "format version 6 cannot hold" "$tmp/err"
# A memory budget: the grid is spaced wider until its probes' bytes fit,
# saying so; the bytes are in the artifact's settings.
printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility","sky_bounce"],"world":{"file":"world.obj"},"probes":{"spacing_m":1,"rays":64,"layers_m":[1,5],"budget_mb":0.05,"bounce_rays":64,"bounce_secondary":8}}' >"$tmp/budget.json"
check "bake within a budget" expect_exit 0 "$skybake" bake "$tmp/budget.json" -o "$tmp/budget"
check "saying the grid was spaced wider" grep -Eq "over probes.budget_mb \(0.05\): [0-9.]+ m apart instead" "$tmp/err"
check "info gives its bytes" expect_exit 0 "$skybake" info "$tmp/budget"
bytes=$(grep -o '"bytes":[0-9]*' "$tmp/out" | head -1 | cut -d: -f2)
check "within the budget ($bytes bytes)" test -n "$bytes" -a "${bytes:-0}" -le 50000 -a "${bytes:-0}" -gt 25000
check "the files hold what the settings say" test "$(($(stat -c %s "$tmp/budget/sky_visibility.sbprobes") + $(stat -c %s "$tmp/budget/sky_bounce.sbprobes")))" -ge "${bytes:-0}"
printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility"],"world":{"file":"world.obj"},"probes":{"spacing_m":0,"positions_m":[[0,1,0],[1,1,0],[2,1,0],[3,1,0],[4,1,0],[5,1,0],[6,1,0],[7,1,0],[8,1,0],[0,1,1],[1,1,1],[2,1,1],[3,1,1]],"budget_mb":0.001}}' >"$tmp/budget_small.json"
check "13 explicit probes, 1040 bytes, over a budget of 1000 are refused" expect_exit 1 "$skybake" bake "$tmp/budget_small.json" -o "$tmp/budget_small"
check "naming probes.budget_mb" grep -q "probes.budget_mb" "$tmp/err"
printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility"],"world":{"file":"world.obj"},"probes":{"budget_mb":0}}' >"$tmp/budget_zero.json"
check "a budget of 0 is refused" expect_exit 2 "$skybake" bake "$tmp/budget_zero.json" -o "$tmp/budget_zero"
check "naming it" grep -q "probes.budget_mb" "$tmp/err"
for bad in '"layers_m":[2,1]' '"layers_m":[]' '"layers_m":[1,2,3,4,5,6,7,8,9]' '"layers_m":[0]' '"spacing_m":0,"positions_m":[[0,1,0]],"layers_m":[1]'; do
    printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility"],"world":{"file":"world.obj"},"probes":{%s}}' "$bad" >"$tmp/bad_layers.json"
    check "probes {$bad} refused" expect_exit 2 "$skybake" bake "$tmp/bad_layers.json" -o "$tmp/bad_layers"
    check "naming probes.layers_m" grep -q "probes.layers_m" "$tmp/err"
done

# Detail where geometry is: a closed room (a box 4 m across and 3 m high,
# its faces facing in, its floor 5 cm over the ground) gets brick columns
# over its footprint and one lattice column around it; the open ground,
# which the layers follow, none. The brick columns are in the file (the
# visibility's version 4, with its sight masks; the bounce's 3), the same on
# 1 and 3 threads; a budget coarsens the detail after the grid, saying so;
# a volume forbids it.
cat >"$tmp/room.obj" <<'OBJ'
v -20 0 -20
v -20 0 20
v 20 0 20
v 20 0 -20
f 1 2 3
f 1 3 4
v -2 0.05 -2
v 2 0.05 -2
v 2 0.05 2
v -2 0.05 2
v -2 3 -2
v 2 3 -2
v 2 3 2
v -2 3 2
f 5 7 6
f 5 8 7
f 9 10 11
f 9 11 12
f 5 10 9
f 5 6 10
f 6 11 10
f 6 7 11
f 7 12 11
f 7 8 12
f 8 9 12
f 8 5 9
OBJ
room() { # extra probes keys
    printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility","sky_bounce"],"world":{"file":"room.obj"},"probes":{"spacing_m":4,"rays":256,"layers_m":[1,5],"bounce_rays":64,"bounce_secondary":8%s}}' "$1"
}
room ',"detail_spacing_m":0.5' >"$tmp/room.json"
check "bake the room with detail" expect_exit 0 "$skybake" bake "$tmp/room.json" -o "$tmp/room1" --threads 1 -v
# 4 m across at 0.5 m: lattice columns -2.5 to 2.5 around it, in bricks of 4
check "detail over the room alone" grep -q "a covered gap; 9 brick columns" "$tmp/err"
# the same box with its faces out is a solid block on the ground: no gap
# in it, none under it (5 cm), so no detail
sed '/^f [5-9]/s/^f \([0-9]*\) \([0-9]*\) \([0-9]*\)$/f \1 \3 \2/; /^f 1[0-2]/s/^f \([0-9]*\) \([0-9]*\) \([0-9]*\)$/f \1 \3 \2/' "$tmp/room.obj" >"$tmp/block.obj"
sed 's/room.obj/block.obj/' "$tmp/room.json" >"$tmp/block.json"
check "bake a solid block with detail" expect_exit 0 "$skybake" bake "$tmp/block.json" -o "$tmp/block" -v
check "no covered gap, no detail" grep -q "0 over a covered gap; 0 brick columns" "$tmp/err"
check "info gives the detail" expect_exit 0 "$skybake" info "$tmp/room1"
check "the settings say so" grep -q '"detail":{"spacing_m":0.5,"brick_columns":9,"probes":' "$tmp/out"
check "the visibility's file is version 4 (sight masks)" sh -c "od -An -tu4 -j8 -N4 '$tmp/room1/sky_visibility.sbprobes' | grep -qw 4"
check "the bounce's is version 5 (binary16)" sh -c "od -An -tu4 -j8 -N4 '$tmp/room1/sky_bounce.sbprobes' | grep -qw 5"
check "verify" expect_exit 0 "$skybake" verify "$tmp/room1"
check "a preview of the layout" expect_exit 0 "$skybake" preview "$tmp/room1" "$tmp/room1.png"
check "1024 pixels across the world" sh -c "python3 '$root/tests/png_stats.py' size '$tmp/room1.png' | grep -qx '1024 1024'"
# the room (4 m of the world's 40) at the middle: brick columns under
# detail probes, no bare ground
check "the detail's columns over the room" sh -c "test \"\$(python3 '$root/tests/png_stats.py' ink '$tmp/room1.png' 492 492 40 40 24 24 24)\" = 1600"
check "bare ground away from it" sh -c "test \"\$(python3 '$root/tests/png_stats.py' ink '$tmp/room1.png' 30 30 40 40 24 24 24)\" -lt 100"
printf '{"atmosphere":{"preset":"earth"},"products":["transmittance"]}' >"$tmp/sky_only.json"
check "a pack without probes" expect_exit 0 "$skybake" bake "$tmp/sky_only.json" -o "$tmp/sky_only" -q
check "has no layout to preview" expect_exit 2 "$skybake" preview "$tmp/sky_only" "$tmp/none.png" --probes
check "saying so" grep -q "no sky_visibility probes" "$tmp/err"
check "nor cubes" expect_exit 2 "$skybake" preview "$tmp/sky_only" "$tmp/none.png"
check "and writes nothing" test ! -e "$tmp/none.png"
cp -r "$tmp/room1" "$tmp/room8"
sed -i 's/"format_version":[[:space:]]*[0-9]*/"format_version": 8/' "$tmp/room8/manifest.json"
check "sight masks in a version 8 pack are refused" expect_exit 1 "$skybake" verify "$tmp/room8"
check "naming them and the version" grep -q "sight masks of detail probes, which format version 8 cannot hold" "$tmp/err"
check "bake it on 3 threads" expect_exit 0 "$skybake" bake "$tmp/room.json" -o "$tmp/room3" --threads 3 -q
check "the same visibility" cmp -s "$tmp/room1/sky_visibility.sbprobes" "$tmp/room3/sky_visibility.sbprobes"
check "the same bounce" cmp -s "$tmp/room1/sky_bounce.sbprobes" "$tmp/room3/sky_bounce.sbprobes"
check "a rebake reuses both" expect_exit 0 "$skybake" bake "$tmp/room.json" -o "$tmp/room1"
check "reused" sh -c "grep -q 'sky_visibility.*reused' '$tmp/err' && grep -q 'sky_bounce.*reused' '$tmp/err'"
check "the reused files are the same" cmp -s "$tmp/room1/sky_bounce.sbprobes" "$tmp/room3/sky_bounce.sbprobes"
check "a reused product keeps the world it was baked against" python3 - "$tmp/room1/manifest.json" "$tmp/room3/manifest.json" <<'PY'
import json, sys
def world(path):
    return [(a.get("world_hash"), a.get("world_path")) for a in json.load(open(path))["artifacts"] if a["name"] == "sky_visibility"][0]
assert world(sys.argv[1])[0] and world(sys.argv[1]) == world(sys.argv[2]), (world(sys.argv[1]), world(sys.argv[2]))
PY
room ',"detail_spacing_m":0.5,"budget_mb":0.15' >"$tmp/room_budget.json"
check "bake the room within a budget" expect_exit 0 "$skybake" bake "$tmp/room_budget.json" -o "$tmp/room_budget"
check "saying the detail was coarsened" grep -q "detail 0.5 m apart would take .* MB, over what probes.budget_mb (0.15) leaves" "$tmp/err"
check "info" expect_exit 0 "$skybake" info "$tmp/room_budget"
bytes=$(sed -n 's/.*"bytes":\([0-9]*\).*/\1/p' "$tmp/out" | head -n 1)
check "within the budget ($bytes bytes)" test -n "$bytes" -a "${bytes:-0}" -le 150000
# A hall 10 m across: 5 cm detail over it would pass a probe file's 2^20
# probes. Alone, refused, naming the cap; under a budget, coarsened.
awk '$1 == "v" && NR > 4 { printf "v %g %s %g\n", 2.5 * $2, $3, 2.5 * $4; next } { print }' "$tmp/room.obj" >"$tmp/hall.obj"
room ',"detail_spacing_m":0.05' | sed 's/room.obj/hall.obj/' >"$tmp/hall.json"
check "5 cm detail over a 10 m hall is refused" expect_exit 1 "$skybake" bake "$tmp/hall.json" -o "$tmp/hall"
check "naming the cap" grep -q "detail 0.05 m apart takes [0-9]* probes; at most 1048576" "$tmp/err"
room ',"detail_spacing_m":0.05,"budget_mb":0.5' | sed 's/room.obj/hall.obj/' >"$tmp/hall_budget.json"
check "under a budget, baked" expect_exit 0 "$skybake" bake "$tmp/hall_budget.json" -o "$tmp/hall_budget"
check "saying the detail was coarsened from past the cap" grep -q "detail 0.05 m apart would take more than a probe file holds" "$tmp/err"
check "no error on the way" sh -c "! grep -q 'error' '$tmp/err'"
room ',"detail_spacing_m":0.5,"detail_volumes":[{"min_m":[-5,-1,-5],"max_m":[5,10,5],"detail":false}]' >"$tmp/room_forbid.json"
check "bake the room, detail forbidden" expect_exit 0 "$skybake" bake "$tmp/room_forbid.json" -o "$tmp/room_forbid" -v
check "no detail" grep -q "(0 in detail)" "$tmp/err"
room ',"detail_spacing_m":2,"detail_volumes":[{"min_m":[10,0,10],"max_m":[14,4,14],"detail":true}]' >"$tmp/room_force.json"
check "bake the room, detail forced on open ground" expect_exit 0 "$skybake" bake "$tmp/room_force.json" -o "$tmp/room_force" -v
check "the forced volume's columns too" sh -c "grep -q 'a covered gap; [0-9]* brick columns' '$tmp/err' && ! grep -q '; 1 brick columns' '$tmp/err'"
for bad in '"detail_spacing_m":0.01' '"detail_spacing_m":-1' '"detail_volumes":[{"min_m":[0,0,0],"max_m":[1,1,1],"detail":true}]' \
    '"detail_spacing_m":1,"detail_volumes":[{"min_m":[0,0,0],"max_m":[0,1,1],"detail":true}]' \
    '"detail_spacing_m":1,"detail_volumes":[{"min_m":[0,0,0],"max_m":[1,1,1]}]' \
    '"detail_spacing_m":1,"detail_volumes":[{"min_m":[0,0,0],"max_m":[1,1,1],"detail":1}]' \
    '"detail_spacing_m":1,"detail_volumes":{}'; do
    printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility"],"world":{"file":"room.obj"},"probes":{%s}}' "$bad" >"$tmp/bad_detail.json"
    check "probes {$bad} refused" expect_exit 2 "$skybake" bake "$tmp/bad_detail.json" -o "$tmp/bad_detail"
    check "naming probes.detail_" grep -q "probes.detail_" "$tmp/err"
done
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 4000 0 0\nv 4001 0 0\nv 4000 1 0\nf 1 2 3\nf 4 5 6\n' >"$tmp/far.obj"
printf '{"atmosphere":{"preset":"earth"},"products":["transmittance","sky_visibility"],"world":{"file":"far.obj"},"probes":{"spacing_m":0,"detail_spacing_m":0.05}}' >"$tmp/fine.json"
check "a lattice past its cap is refused before any bake" expect_exit 1 "$skybake" bake "$tmp/fine.json" -o "$tmp/fine"
check "before the transmittance" sh -c "! grep -q 'transmittance' '$tmp/err'"
check "naming probes.detail_spacing_m" grep -q "raise probes.detail_spacing_m" "$tmp/err"

# Tiles: a level of huts and a room on a 100 m ground, in tiles 16 m
# across, rays reaching 4 m. Moving one hut 4 m rebakes the visibility of
# the tiles whose probes' box, grown by what they see (0.6 of the spacing
# for a push out, then the reach: 6.41 m), meets the hut's box before or
# after, and no other (counted here from the tile list); the bounce's grow
# by twice the reach from where the probes ended up (a push out moves a
# grid probe at most 2 m: 8.01 +- 2 m); the pack is then byte for byte a
# forced bake's. A tile baked alone (--tile) holds that bake's bytes, the
# rest unbaked; a bake into that pack keeps it and bakes the rest.
printf 'v -50 0 -50\nv -50 0 50\nv 50 0 50\nv 50 0 -50\nf 1 2 3\nf 1 3 4\n' >"$tmp/ground.obj"
sed -n '/^v -2 0.05 -2$/,$p' "$tmp/room.obj" | awk '/^f/ { printf "f %d %d %d\n", $2 - 4, $3 - 4, $4 - 4; next } { print }' >"$tmp/room_only.obj"
level() { # the moving hut's x
    printf '{"version":1,"ground":false,"instances":[{"file":"ground.obj"},{"file":"hut.json","translate_m":[-30,0,-30]},{"file":"hut.json","translate_m":[%s,0,10]},{"file":"hut.json","translate_m":[30,0,-20]},{"file":"room_only.obj","translate_m":[-30,0,25]}]}' "$1" >"$tmp/tiles-world.json"
}
level 20
printf '{"version":1,"name":"tiles","atmosphere":{"preset":"earth"},"products":["sky_visibility","sky_bounce","sun_bounce"],"world":{"file":"tiles-world.json"},"probes":{"spacing_m":4,"layers_m":[1.5,6],"rays":64,"bounce_rays":64,"bounce_secondary":8,"sun_rays":64,"detail_spacing_m":1,"tile_m":16,"reach_m":4}}' >"$tmp/tiles.json"
check "bake a level in tiles" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/tiles"
check "every tile baked" grep -q "sky_visibility: \([0-9]*\) tiles: \1 baked, 0 kept" "$tmp/err"
check "with detail" grep -q "([1-9][0-9]* in detail)" "$tmp/err"
check "the visibility's file is version 6" sh -c "od -An -tu4 -j8 -N4 '$tmp/tiles/sky_visibility.sbprobes' | grep -qw 6"
check "verify" expect_exit 0 "$skybake" verify "$tmp/tiles"
check "info lists the tiles" expect_exit 0 "$skybake" info "$tmp/tiles" --json
cp "$tmp/out" "$tmp/tiles-before.json"
level 24
check "one hut moved 4 m: rebake" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/tiles"
baked=$(sed -n 's/.*sky_visibility: [0-9]* tiles: \([0-9]*\) baked, \([0-9]*\) kept.*/\1/p' "$tmp/err")
bounce_baked=$(sed -n 's/.*sky_bounce: [0-9]* tiles: \([0-9]*\) baked, \([0-9]*\) kept.*/\1/p' "$tmp/err")
sun_baked=$(sed -n 's/.*sun_bounce: [0-9]* tiles: \([0-9]*\) baked, \([0-9]*\) kept.*/\1/p' "$tmp/err")
expected=$(python3 - "$tmp/tiles-before.json" <<'PY'
import json, math, sys
tiles = [a for a in json.load(open(sys.argv[1]))["artifacts"] if a["name"] == "sky_visibility"][0]["tiles"]
boxes = [(20 - 2, 20 + 4, 8, 12), (24 - 2, 24 + 4, 8, 12)]  # the hut (a 4 m box, a cube 3 m to its +x) before, after
columns = [4 * k for k in range(-13, 14)]  # the grid: -52 to 52 m, 4 m apart
def touched(margin):
    def span(t):
        c = [x for x in columns if math.floor(x / 16) == t]
        return min(c) - margin, max(c) + margin
    n = 0
    for t in tiles:
        (x0, x1), (z0, z1) = span(t["x"]), span(t["z"])
        n += any(x0 <= b[1] and x1 >= b[0] and z0 <= b[3] and z1 >= b[2] for b in boxes)
    return n
print(touched(0.6 * 4 + 4 + 0.01), touched(2 * 4 + 0.01 - 2), touched(2 * 4 + 0.01 + 2), len(tiles))
PY
)
read -r want_vis want_lo want_hi all_tiles <<EOF
$expected
EOF
check "the tiles around the hut rebaked: $baked of $all_tiles (expected $want_vis)" test -n "$baked" -a "$baked" = "$want_vis"
check "and no more than a tenth" test "$((10 * ${baked:-99}))" -le "$all_tiles"
check "the bounce's: $bounce_baked (expected $want_lo to $want_hi)" test -n "$bounce_baked" -a "${bounce_baked:-0}" -ge "$want_lo" -a "${bounce_baked:-99}" -le "$want_hi"
check "the sun's bounce the same tiles: $sun_baked" test -n "$sun_baked" -a "$sun_baked" = "$bounce_baked"
check "a forced bake of the moved level" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/tiles-full" --force -q
check "the same visibility, byte for byte" cmp -s "$tmp/tiles/sky_visibility.sbprobes" "$tmp/tiles-full/sky_visibility.sbprobes"
check "the same bounce, byte for byte" cmp -s "$tmp/tiles/sky_bounce.sbprobes" "$tmp/tiles-full/sky_bounce.sbprobes"
check "the same sun bounce, byte for byte" cmp -s "$tmp/tiles/sun_bounce.sbprobes" "$tmp/tiles-full/sun_bounce.sbprobes"
check "a tile baked alone" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/tile-one" --tile -2,1
check "one baked, the rest left" grep -q "sky_visibility: \([0-9]*\) tiles: 1 baked, 0 kept (their keys unchanged), [1-9][0-9]* left" "$tmp/err"
check "verify the partial pack" expect_exit 0 "$skybake" verify "$tmp/tile-one"
check "info" expect_exit 0 "$skybake" info "$tmp/tile-one" --json
cp "$tmp/out" "$tmp/tile-one.json"
check "info of the whole" expect_exit 0 "$skybake" info "$tmp/tiles-full" --json
check "the tile (the room's, with detail) holds the whole bake's bytes" python3 - "$tmp/tile-one.json" "$tmp/out" <<'PY'
import json, sys
def tiles(path, name):
    return {(t["x"], t["z"]): t for a in json.load(open(path))["artifacts"] if a["name"] == name for t in a["tiles"]}
for name in ("sky_visibility", "sky_bounce", "sun_bounce"):
    one, whole = tiles(sys.argv[1], name), tiles(sys.argv[2], name)
    assert one.keys() == whole.keys(), name
    assert one[(-2, 1)]["baked"] and one[(-2, 1)]["content"] == whole[(-2, 1)]["content"], (name, one[(-2, 1)])
    assert one[(-2, 1)]["key"] == whole[(-2, 1)]["key"], name
    assert not any(t["baked"] for k, t in one.items() if k != (-2, 1)), name
PY
check "a bake into the partial pack" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/tile-one"
check "keeps the tile" grep -q "sky_visibility: [0-9]* tiles: [0-9]* baked, 1 kept (their keys unchanged), 0 left" "$tmp/err"
check "and is the whole bake" cmp -s "$tmp/tile-one/sky_visibility.sbprobes" "$tmp/tiles-full/sky_visibility.sbprobes"
# A farm: two machines bake a tile each into packs of their own; a third
# merges them (--from) casting nothing, then bakes the rest into the merge
check "machine a bakes tile -2,1" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/farm-a" --tile -2,1 -q
check "machine b bakes tile 1,0" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/farm-b" --tile 1,0 -q
check "a merge of the two" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/farm" --tile -2,1 --tile 1,0 --from "$tmp/farm-a" --from "$tmp/farm-b"
check "casts nothing, keeps both" grep -q "sky_visibility: [0-9]* tiles: 0 baked, 2 kept (their keys unchanged), [1-9][0-9]* left" "$tmp/err"
check "the bounce's likewise" grep -q "sky_bounce: [0-9]* tiles: 0 baked, 2 kept (their keys unchanged), [1-9][0-9]* left" "$tmp/err"
check "the rest baked into the merge" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/farm"
check "keeps the two" grep -q "sky_visibility: [0-9]* tiles: [0-9]* baked, 2 kept (their keys unchanged), 0 left" "$tmp/err"
check "and is the whole bake" sh -c "cmp -s '$tmp/farm/sky_visibility.sbprobes' '$tmp/tiles-full/sky_visibility.sbprobes' && cmp -s '$tmp/farm/sky_bounce.sbprobes' '$tmp/tiles-full/sky_bounce.sbprobes' && cmp -s '$tmp/farm/sun_bounce.sbprobes' '$tmp/tiles-full/sun_bounce.sbprobes'"
check "--from with --force is refused" expect_exit 2 "$skybake" bake "$tmp/tiles.json" -o "$tmp/farm" --force --from "$tmp/farm-a"
check "--from a pack that is not there is said" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/farm" --from "$tmp/nowhere"
check "naming it" grep -q "nowhere (--from): no pack there" "$tmp/err"
check "a tile of no probe is said" expect_exit 0 "$skybake" bake "$tmp/tiles.json" -o "$tmp/tile-none" --tile 40,40 -q
check "--tile needs tiles" expect_exit 2 "$skybake" bake "$tmp/room.json" -o "$tmp/n" --tile 0,0
check "--tile X,Z" expect_exit 2 "$skybake" bake "$tmp/tiles.json" -o "$tmp/n" --tile 0
for bad in '"tile_m":0.5' '"tile_m":-1' '"tile_m":2e4' '"reach_m":-1' '"tile_m":16,"positions_m":[[0,1,0]]'; do
    printf '{"atmosphere":{"preset":"earth"},"products":["sky_visibility"],"world":{"file":"room.obj"},"probes":{"spacing_m":4,%s}}' "$bad" >"$tmp/bad_tiles.json"
    check "probes {$bad} refused" expect_exit 2 "$skybake" bake "$tmp/bad_tiles.json" -o "$tmp/bad_tiles"
    check "naming probes.tile_m or reach_m" grep -q "probes\.\(tile_m\|reach_m\)" "$tmp/err"
done

echo "probes cli: $checks checks, $fails failed"
echo "$((checks - fails)) passed, $fails failed"
[ "$fails" = 0 ]

#!/bin/sh
# Every shader header stands alone: each GLSL header (lib/, bake/, view/)
# compiles when it is the only thing a shader includes (it includes what it
# uses), and each C/GLSL contract (config.h, view/*_gpu.h) compiles alone
# both as GLSL and as C11. Six GLSL headers are templates and say so:
# bvh.glsl (its includer declares the node and triangle buffers),
# surface.glsl (after bvh.glsl, at the includer's SURFACE_BINDING), texels.glsl
# (at the includer's TEXELS_BINDING_*), prefilter.glsl (after the
# includer's prefilter_fetch and PREFILTER_THREADS), relight.glsl (after
# atmosphere.glsl, bvh.glsl and the includer's sky_sh) and
# sphere.glsl (a kernel's body: it sets the workgroup size).
# Usage: test_shader_headers.sh GLSLANG SOURCE_ROOT [CC]
set -u
glslang=$1
root=$2
cc=${3:-cc}
shaders=$root/shaders
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0
failed=0
includes="-I$shaders -I$shaders/lib -I$shaders/bake -I$shaders/view"
for header in "$shaders"/lib/*.glsl "$shaders"/bake/*.glsl "$shaders"/view/*.glsl "$shaders"/config.h \
    "$shaders"/view/*_gpu.h; do
    name=$(basename "$header")
    case $name in bvh.glsl | surface.glsl | texels.glsl | prefilter.glsl | relight.glsl | sphere.glsl) continue ;; esac
    printf '#version 450\n#extension GL_GOOGLE_include_directive : require\n#include "%s"\nlayout(local_size_x = 1) in;\nvoid main() {}\n' \
        "$name" >"$tmp/t.comp"
    # shellcheck disable=SC2086
    if "$glslang" --target-env vulkan1.1 $includes -S comp "$tmp/t.comp" -o "$tmp/t.spv" >"$tmp/log" 2>&1; then
        passed=$((passed + 1))
    else
        echo "FAILED: $name does not compile alone as GLSL:"
        grep -i error "$tmp/log" | head -5
        failed=$((failed + 1))
    fi
    case $name in *.h) ;; *) continue ;; esac
    printf '#include "%s"\n' "$name" >"$tmp/t.c"
    # shellcheck disable=SC2086
    if "$cc" -std=c11 -Wall -Werror -fsyntax-only $includes "$tmp/t.c" >"$tmp/log" 2>&1; then
        passed=$((passed + 1))
    else
        echo "FAILED: $name does not compile alone as C11:"
        head -5 "$tmp/log"
        failed=$((failed + 1))
    fi
done
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]

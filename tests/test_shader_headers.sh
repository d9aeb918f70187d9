#!/bin/sh
# Every GLSL header stands alone: it compiles when it is the only thing a
# shader includes (it includes what it uses). Two are templates and say so:
# bvh.glsl (its includer declares the node and triangle buffers) and
# sphere.glsl (a kernel's body: it sets the workgroup size).
# Usage: test_shader_headers.sh GLSLANG SOURCE_ROOT
set -u
glslang=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0
failed=0
for header in "$root"/shaders/*.glsl; do
    name=$(basename "$header")
    case $name in bvh.glsl | sphere.glsl) continue ;; esac
    printf '#version 450\n#extension GL_GOOGLE_include_directive : require\n#include "%s"\nlayout(local_size_x = 1) in;\nvoid main() {}\n' \
        "$name" >"$tmp/t.comp"
    if "$glslang" --target-env vulkan1.1 -I"$root/shaders" -S comp "$tmp/t.comp" -o "$tmp/t.spv" >"$tmp/log" 2>&1; then
        passed=$((passed + 1))
    else
        echo "FAILED: $name does not compile alone:"
        grep -i error "$tmp/log" | head -5
        failed=$((failed + 1))
    fi
done
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]

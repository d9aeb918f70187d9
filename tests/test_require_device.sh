#!/bin/sh
# CI cannot pass by skipping: with no Vulkan device a GPU test skips (77)
# on a developer's machine, and fails when SKYBAKE_REQUIRE_DEVICE=1, as
# .ci/run sets it. Every GPU test program returns through the one helper
# that decides (tests/harness_vk.h, test_no_device).
# Usage: test_require_device.sh SOURCE_ROOT GPU_TEST...
set -u
root=$1
shift
. "$root/tests/cli_lib.sh"
unset SKYBAKE_REQUIRE_DEVICE
nodevice="env VK_DRIVER_FILES=/nonexistent.json VK_ICD_FILENAMES=/nonexistent.json"
for program in "$@"; do
    name=$(basename "$program")
    check "$name with no device skips" expect_exit 77 $nodevice "$program"
    check "$name with no device and SKYBAKE_REQUIRE_DEVICE=1 fails" \
        expect_exit 1 $nodevice SKYBAKE_REQUIRE_DEVICE=1 "$program"
    check "$name says why" grep -q "SKYBAKE_REQUIRE_DEVICE=1" "$tmp/err"
done
check "no GPU test skips but through test_no_device" test -z "$(grep -l 'return TEST_SKIP' "$root"/tests/test_*.c)"
check "every program that makes a Vulkan context can fail for want of one" \
    test -z "$(grep -L 'test_no_device' $(grep -l 'test_vulkan(' "$root"/tests/test_*.c))"
check ".ci/run requires a device" grep -q "SKYBAKE_REQUIRE_DEVICE=1" "$root/.ci/run"
echo "$((checks - fails)) passed, $fails failed"
[ "$fails" = 0 ]

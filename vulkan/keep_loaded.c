/*
 * Sanitizer builds only (vulkan/meson.build): keep every shared library
 * loaded until the process ends. The Vulkan loader unloads the driver when
 * the instance is destroyed, before LeakSanitizer reports, which leaves the
 * driver's frames as "<unknown module>" that no suppression can name
 * (tests/lsan.supp names the libraries). Defined in each program, this
 * dlclose takes precedence over libc's for the loader's calls too.
 */
#include <dlfcn.h>

int dlclose(void *handle)
{
    (void)handle;
    return 0;
}

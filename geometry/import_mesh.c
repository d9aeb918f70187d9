/* skybake-import-mesh: the helper program in which assimp reads a mesh file
 * for sb_mesh_import, apart from the program that loads it (formats/
 * sandbox.h says why; import_mesh.h, what they say to each other). */
#include "import_mesh.h"
#include "sandbox.h"

int main(int argc, char **argv)
{
    return sb_sandbox_main(argc, argv, sb_mesh_import_task);
}

/* skybake-read-vdb: the helper program in which OpenVDB parses a VDB file
 * for sb_vdb_read, apart from the program that reads it (sandbox.h says
 * why; read_vdb.h, what they say to each other). */
#include "read_vdb.h"
#include "sandbox.h"

int main(int argc, char **argv)
{
    return sb_sandbox_main(argc, argv, sb_vdb_read_task);
}

/* skybake-vdb: the helper program in which OpenVDB reads and writes VDB
 * files for vdb.h, apart from the program that asks (vdb_helper.h says
 * what they say to each other; sandbox.h, why a reader is apart). */
#include "vdb_helper.h"
#include "sandbox.h"

int main(int argc, char **argv)
{
    return sb_sandbox_main(argc, argv, sb_vdb_task);
}

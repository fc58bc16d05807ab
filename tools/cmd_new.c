/* placeholder replaced below */
#include "cli.h"
int fmb_cmd_new(int argc, char** argv) { (void)argc; (void)argv; return 2; }

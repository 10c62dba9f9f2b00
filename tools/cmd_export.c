#include <stdio.h>
#include "tools/cli.h"
int iris_cmd_export(int argc, char **argv) { (void)argc; (void)argv; fprintf(stderr, "iris: export: not implemented yet\n"); return IRIS_EXIT_FAILURE; }

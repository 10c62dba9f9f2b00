#include <stdio.h>
#include "tools/cli.h"
int iris_cmd_render(int argc, char **argv) { (void)argc; (void)argv; fprintf(stderr, "iris: render: not implemented yet\n"); return IRIS_EXIT_FAILURE; }

/* cmd_types.c — `flexmbd types`: the registered body and joint types and their outputs. */
#include <stdio.h>

#include "cli.h"

int fmb_cmd_types(int argc, char** argv) {
  (void)argc;
  (void)argv;
  const fmbRegistry* reg = fmb_cli_registry();
  printf("bodies:\n");
  for (int i = 0; i < reg->nbodies; ++i) {
    printf("  %s", reg->bodies[i]->name);
    const char* const* o = reg->bodies[i]->output_names;
    if (o && o[0]) {
      printf("  (outputs:");
      for (; *o; ++o) printf(" %s", *o);
      printf(")");
    }
    printf("\n");
  }
  printf("joints and forces:\n");
  for (int i = 0; i < reg->njoints; ++i) printf("  %s\n", reg->joints[i]->name);
  return 0;
}

/* pattern.h — pattern.c: the fixed sparsity pattern of the Newton matrix, built at load (scene.c)
 * and freed with the model. Out of internal.h, which every engine file includes, because only
 * scene.c calls these. */
#ifndef FMB_PATTERN_H
#define FMB_PATTERN_H

#include "internal.h"

int fmb_pattern_build(fmbModel* m);
void fmb_pattern_free(fmbModel* m);

#endif

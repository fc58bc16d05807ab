/* view.h — `flexmbd view`: its options (tools/cmd_view.c) and the page made from them
 * (tools/view_page.c). */
#ifndef FLEXMBD_VIEW_H
#define FLEXMBD_VIEW_H
#include "cli.h"

typedef struct fmbViewArgs {
  fmbCliScene s; /* first: the scene, --set, --plugin */
  const char *csv, *out, *columns;
  const char* model; /* --model M: the run of model M in a `run --models` CSV (its NAME@M columns) */
  double scale;      /* --scale S: the beams' deformation drawn S times */
} fmbViewArgs;

/* the HTML page of the run a->csv drawn with a->s's scene into a->out: 0, or an exit code after
   saying why */
int fmb_view_page(const fmbViewArgs* a);
#endif

/* testlib.h — the tests' small toolkit: checks that report file:line and the values, running a
 * scene in-process, and reading the CSV it wrote back into named columns. */
#ifndef FLEXMBD_TESTLIB_H
#define FLEXMBD_TESTLIB_H
#include <math.h>
#include <stdio.h>

#include "builtin.h"
#include "flexmbd_cli.h"
#include "flexmbd_plugin.h"

#include "check.h"

typedef struct {
  int ncol, nrow;
  char** names;
  double* data; /* column-major: column c at data + c * nrow */
} fmbtCsv;

/* scene path relative to the source tree */
const char* fmbt_path(const char* rel, char* buf, size_t len);
/* run SCENE (path relative to the source tree) with overrides, writing OUT (in the build's test
   output folder); returns fmb_run's code (or the load error's), stats and diag filled */
int fmbt_run(const char* scene_rel, const char* const* overrides, int noverrides, const char* out_name, fmbStats* st,
             fmbDiag* diag);
/* run and read the CSV back; returns the run code, c filled (empty on load failure) */
int fmbt_run_read(const char* scene_rel, const char* const* overrides, int noverrides, const char* out_name, fmbtCsv* c,
                  fmbStats* st);
int fmbt_csv_read(const char* path, fmbtCsv* c);
/* the column called name, or NULL (and a failure recorded) */
const double* fmbt_col(const fmbtCsv* c, const char* name);
void fmbt_csv_free(fmbtCsv* c);
/* angular frequency from the zero crossings of column col for t >= t0 (linear interpolation
   between rows); *ncross = the crossings used; NaN with fewer than two */
double fmbt_crossing_frequency(const fmbtCsv* c, const char* col, double t0, int* ncross);
/* a driven beam's energy balance: with its root pinned at the origin and no gravity the only
   torque about the pin is the drive's, so dp_theta/dt = tau and the drive's work is
   W = int tau omega dt = int omega dp_theta (p_theta = BODY.ang_momentum = dT/dtheta').
   max |E(t) - E(0) - W(t)| / max |E| over the rows (trapezoidal rule), from the columns
   energy.total, BODY.omega and BODY.ang_momentum */
double fmbt_energy_balance(const fmbtCsv* c, const char* body);
const char* fmbt_out_path(const char* name, char* buf, size_t len);
/* a whole file into memory (NUL-terminated, *len bytes; free() it); NULL when unreadable */
char* fmbt_slurp(const char* path, size_t* len);

#endif

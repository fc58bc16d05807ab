/* sweep_load.c — loads libflexmbd_sweep.so (MPI, HDF5) for `flexmbd sweep` (and for `flexmbd
 * campbell` under mpirun/srun) only, and stands in
 * for what it lacks: no MPI = the local pool, no HDF5 = no sweep.h5 (runs.csv and table.csv are
 * always written). RTLD_GLOBAL: Open MPI's own components, loaded later, need libmpi's symbols. */
#include <dlfcn.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sweep.h"

#ifndef FLEXMBD_LIBDIR
#define FLEXMBD_LIBDIR "lib"
#endif

int fmb_sweep_launched_by_mpi(void) {
  /* set by Open MPI's mpirun, by PMI/PMIx launchers (srun) */
  static const char* const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"};
  for (size_t k = 0; k < sizeof vars / sizeof vars[0]; ++k)
    if (getenv(vars[k])) return 1;
  return 0;
}

static int no_mpi_init(fmbFarmTransport* t) {
  t->rank = 0, t->nranks = 1;
  return 0;
}
static void no_mpi_finalize(int rc) { (void)rc; }
static int no_h5(const fmbSweep* sw, const char* path) {
  (void)path;
  (void)sw;
  return 1;
}

const fmbSweepExtension* fmb_sweep_extension_load(int load) {
  static fmbSweepExtension ext = {0, 0, no_mpi_init, no_mpi_finalize, no_h5};
  static int loaded;
  if (loaded || !load) return &ext;
  loaded = 1;
  char exe[4096], path[4400];
  ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n <= 0) return &ext;
  exe[n] = '\0';
  const char* dir = dirname(exe);
  const char* const where[2] = {"%s/libflexmbd_sweep.so", "%s/../" FLEXMBD_LIBDIR "/flexmbd/libflexmbd_sweep.so"};
  void* h = NULL;
  for (int k = 0; k < 2 && !h; ++k) {
    snprintf(path, sizeof path, where[k], dir);
    if (access(path, R_OK) == 0) {
      h = dlopen(path, RTLD_NOW | RTLD_GLOBAL);
      if (!h) fprintf(stderr, "flexmbd sweep: warning: %s does not load (%s): no MPI, no sweep.h5\n", path, dlerror());
    }
  }
  const fmbSweepExtension* (*entry)(void) = NULL;
  if (h) *(void**)&entry = dlsym(h, "fmb_sweep_extension");
  if (!entry) return &ext;
  const fmbSweepExtension* m = entry();
  if (m->has_mpi) {
    ext.has_mpi = 1;
    ext.mpi_init = m->mpi_init;
    ext.mpi_finalize = m->mpi_finalize;
  }
  if (m->has_hdf5) ext.has_hdf5 = 1, ext.write_h5 = m->write_h5;
  return &ext;
}

int fmb_farm_mpi_start(const char* who, fmbFarmTransport* t) {
  memset(t, 0, sizeof *t);
  t->nranks = 1;
  if (!fmb_sweep_launched_by_mpi()) return 0;
  const fmbSweepExtension* ext = fmb_sweep_extension_load(1);
  if (!ext->has_mpi) { /* every rank would do the whole work into the same files */
    const char* r = getenv("OMPI_COMM_WORLD_RANK");
    if (!r) r = getenv("PMIX_RANK");
    if (!r) r = getenv("PMI_RANK");
    if (r && atoi(r) > 0) return -1;
    fprintf(stderr,
            "flexmbd %s: warning: started by mpirun/srun, but built without MPI: rank 0 works alone, the other ranks "
            "leave\n",
            who);
    return 0;
  }
  if (ext->mpi_init(t) != 0) {
    memset(t, 0, sizeof *t);
    t->nranks = 1;
    return 0;
  }
  return t->nranks > 1;
}

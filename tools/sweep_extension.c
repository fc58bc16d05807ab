/* sweep_extension.c — the one exported symbol of libflexmbd_sweep.so, the module that brings MPI
 * and HDF5 to `flexmbd sweep` (sweep.h says why they are not linked into the program). */
#include "sweep.h"

__attribute__((visibility("default"))) const fmbSweepExtension* fmb_sweep_extension(void);
const fmbSweepExtension* fmb_sweep_extension(void) {
  static const fmbSweepExtension ext = {
#ifdef FLEXMBD_HAVE_MPI
      .has_mpi = 1,
      .mpi_init = fmb_sweep_mpi_init,
      .mpi_finalize = fmb_sweep_mpi_finalize,
#endif
#ifdef FLEXMBD_HAVE_HDF5
      .has_hdf5 = 1,
      .write_h5 = fmb_sweep_write_h5,
#endif
  };
  return &ext;
}

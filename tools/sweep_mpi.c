/* sweep_mpi.c — the farm's messages over MPI (farm.h): how `flexmbd sweep` and `flexmbd campbell`
 * share their tasks among the ranks of mpirun or srun. Built only with MPI (FLEXMBD_HAVE_MPI),
 * into the module libflexmbd_sweep.so (sweep.h says why); without it, or when not started by
 * mpirun/srun, the farm is this process alone (no MPI_Init: a singleton start costs 0.3 s). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "sweep.h"

#ifdef FLEXMBD_HAVE_MPI
#include <mpi.h>

static int mpi_up;

static int mpi_poll(int* source, int* tag, char** bytes, int* len) {
  int flag = 0;
  MPI_Status st;
  if (MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st) != MPI_SUCCESS || !flag) return 0;
  MPI_Get_count(&st, MPI_CHAR, len);
  *bytes = malloc((size_t)*len + 1);
  if (!*bytes) return 0; /* left waiting: taken when memory is back */
  MPI_Recv(*bytes, *len, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  (*bytes)[*len] = '\0';
  *source = st.MPI_SOURCE, *tag = st.MPI_TAG;
  return 1;
}

static void mpi_send(int dest, int tag, const void* bytes, int len) {
  MPI_Send(bytes, len, MPI_CHAR, dest, tag, MPI_COMM_WORLD);
}

static int mpi_bcast_int(int value) {
  MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return value;
}

int fmb_sweep_mpi_init(fmbFarmTransport* t) {
  if (MPI_Init(NULL, NULL) != MPI_SUCCESS) {
    fprintf(stderr, "flexmbd: MPI_Init failed\n");
    return -1;
  }
  mpi_up = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &t->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &t->nranks);
  t->poll = mpi_poll, t->send = mpi_send, t->bcast_int = mpi_bcast_int;
  return 0;
}

void fmb_sweep_mpi_finalize(int rc) {
  if (!mpi_up) return;
  mpi_up = 0;
  if (rc == FMB_EXIT_INTERRUPTED) /* the other ranks may be waiting on us: end the job */
    MPI_Abort(MPI_COMM_WORLD, rc);
  MPI_Finalize();
}

#endif

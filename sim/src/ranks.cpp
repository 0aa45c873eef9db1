#include "granmem/sim/ranks.hpp"

#include <cstdlib>

#include "granmem/core/error.hpp"

#ifdef GRANMEM_MPI
#include <mpi.h>
#endif

namespace granmem {
namespace {

#ifdef GRANMEM_MPI
// Open MPI's, MPICH's and Slurm's PMI variables: set for the processes a launcher starts.
bool under_launcher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "SLURM_PROCID"}) {
    if (std::getenv(name)) return true;
  }
  return false;
}

void finalize() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

Ranks start() {
  if (!under_launcher()) return {};
  int provided = 0;
  // Runs are dealt to threads inside a rank; only the thread that started MPI calls it.
  if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    throw Error("MPI: initialisation failed");
  }
  std::atexit(finalize);
  Ranks r;
  MPI_Comm_rank(MPI_COMM_WORLD, &r.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &r.size);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, r.rank, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &r.on_node);
  MPI_Comm_free(&node);
  return r;
}
#endif

}  // namespace

Ranks mpi_ranks() {
#ifdef GRANMEM_MPI
  static const Ranks ranks = start();
  return ranks;
#else
  return {};
#endif
}

void mpi_barrier() {
#ifdef GRANMEM_MPI
  if (mpi_ranks().size > 1) MPI_Barrier(MPI_COMM_WORLD);
#endif
}

bool mpi_any(bool failed) {
#ifdef GRANMEM_MPI
  if (mpi_ranks().size > 1) {
    int mine = failed ? 1 : 0, any = 0;
    MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return any != 0;
  }
#endif
  return failed;
}

}  // namespace granmem

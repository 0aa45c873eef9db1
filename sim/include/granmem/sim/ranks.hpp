#pragma once

namespace granmem {

// This process's place among the processes of an MPI job: rank 0 of 1 unless granmem was
// built with -DGRANMEM_MPI=ON and started by an MPI launcher (mpirun, srun), which the
// launcher's environment tells. A plain run never starts MPI.
struct Ranks {
  int rank = 0;
  int size = 1;
  int on_node = 1;  // ranks sharing this machine (its cores)
  bool root() const { return rank == 0; }
};

// Starts MPI on the first call under a launcher (and ends it at exit).
Ranks mpi_ranks();

// Every rank waits for the others (nothing without MPI).
void mpi_barrier();

// True on every rank if any rank passes true (`failed` itself without MPI).
bool mpi_any(bool failed);

}  // namespace granmem

// The few MPI calls a sweep needs, behind a small class so that the rest of
// the sweep compiles without MPI (mpi_transport.cpp is built only where MPI
// was found; mpi_transport_none.cpp otherwise).
//
// Only the calling (main) thread of a rank talks MPI (MPI_THREAD_FUNNELED):
// the runs execute on worker threads that never call MPI. Nothing blocks in
// MPI: OpenMPI's blocking receives spin at 100 % CPU, which would take a core
// away from the runs, so every receive is an MPI_Iprobe followed by a sleep
// when there is nothing to read.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace crowdrecon::sweep {

// True if this process was started by mpirun / mpiexec / srun as an MPI rank
// (OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK in the environment).
bool LaunchedAsMpiRank();

class MpiTransport {
 public:
  // MPI_Init_thread the first time in a process (MPI_Finalize at its exit);
  // throws InputError if this crowdrecon was built without MPI.
  MpiTransport();
  ~MpiTransport();
  MpiTransport(const MpiTransport&) = delete;
  MpiTransport& operator=(const MpiTransport&) = delete;

  int rank() const;
  int size() const;

  // Worker rank -> rank 0: a message (a request for work, with the row of the
  // run just finished, if any).
  void SendToRoot(const std::string& bytes);
  // Rank 0: a pending worker message, if any (never blocks).
  bool PollFromWorkers(int* source, std::string* bytes);
  // Rank 0 -> worker rank: a control code (a run index, or a negative code).
  void SendControl(int destination, std::int64_t code);
  // Worker rank: a pending control code from rank 0, if any (never blocks).
  bool PollControl(std::int64_t* code);
  // Every rank: true where `ok` is true on every rank (collective).
  bool AllOk(bool ok);
  // Every rank: rank 0's `ok` (collective).
  bool RootOk(bool ok);
  // Every rank: rank 0's `status` (collective; a small non-negative code).
  int RootStatus(int status);
  // Ends every rank at once, after a fatal error on one of them.
  [[noreturn]] void Abort(int code);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crowdrecon::sweep

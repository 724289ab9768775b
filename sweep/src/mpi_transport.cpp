#include "mpi_transport.hpp"

#include <mpi.h>

#include <cstdlib>
#include <vector>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::sweep {

namespace {
constexpr int kTagToRoot = 1;
constexpr int kTagControl = 2;
}  // namespace

bool LaunchedAsMpiRank() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (const char* v = std::getenv(name); v && *v) return true;
  return false;
}

struct MpiTransport::Impl {
  int rank = 0;
  int size = 1;
};

// MPI is initialised once per process and finalised at its exit: a
// calibration runs many sweeps in one process, and MPI cannot be initialised
// again once finalised.
extern "C" void FinalizeMpiAtExit() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

MpiTransport::MpiTransport() : impl_(std::make_unique<Impl>()) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    if (provided < MPI_THREAD_FUNNELED) {
      MPI_Finalize();
      throw InputError("MPI: the MPI library does not allow threads (MPI_THREAD_FUNNELED); run with --jobs 1 under "
                       "a thread-capable MPI");
    }
    std::atexit(FinalizeMpiAtExit);
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &impl_->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &impl_->size);
}

MpiTransport::~MpiTransport() = default;

int MpiTransport::rank() const { return impl_->rank; }
int MpiTransport::size() const { return impl_->size; }

void MpiTransport::SendToRoot(const std::string& bytes) {
  MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, 0, kTagToRoot, MPI_COMM_WORLD);
}

bool MpiTransport::PollFromWorkers(int* source, std::string* bytes) {
  int flag = 0;
  MPI_Status status;
  MPI_Iprobe(MPI_ANY_SOURCE, kTagToRoot, MPI_COMM_WORLD, &flag, &status);
  if (!flag) return false;
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  std::vector<char> buffer(static_cast<std::size_t>(count));
  MPI_Recv(buffer.data(), count, MPI_BYTE, status.MPI_SOURCE, kTagToRoot, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  *source = status.MPI_SOURCE;
  bytes->assign(buffer.begin(), buffer.end());
  return true;
}

void MpiTransport::SendControl(int destination, std::int64_t code) {
  MPI_Send(&code, 1, MPI_INT64_T, destination, kTagControl, MPI_COMM_WORLD);
}

bool MpiTransport::PollControl(std::int64_t* code) {
  int flag = 0;
  MPI_Status status;
  MPI_Iprobe(0, kTagControl, MPI_COMM_WORLD, &flag, &status);
  if (!flag) return false;
  MPI_Recv(code, 1, MPI_INT64_T, 0, kTagControl, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return true;
}

bool MpiTransport::AllOk(bool ok) {
  int mine = ok ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all == 1;
}

bool MpiTransport::RootOk(bool ok) { return RootStatus(ok ? 1 : 0) == 1; }

int MpiTransport::RootStatus(int status) {
  MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return status;
}

void MpiTransport::Abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::abort();  // not reached
}

}  // namespace crowdrecon::sweep

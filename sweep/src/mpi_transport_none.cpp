// Built where CMake found no MPI: a sweep started by mpirun says so and stops.
#include <cstdlib>

#include "crowdrecon/common/error.hpp"
#include "mpi_transport.hpp"

namespace crowdrecon::sweep {

bool LaunchedAsMpiRank() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (const char* v = std::getenv(name); v && *v) return true;
  return false;
}

struct MpiTransport::Impl {};

MpiTransport::MpiTransport() {
  throw InputError("started by mpirun, but this crowdrecon was built without MPI (install libopenmpi-dev, "
                   "reconfigure and rebuild); run the sweep without mpirun to use the local cores");
}
MpiTransport::~MpiTransport() = default;
int MpiTransport::rank() const { return 0; }
int MpiTransport::size() const { return 1; }
void MpiTransport::SendToRoot(const std::string&) {}
bool MpiTransport::PollFromWorkers(int*, std::string*) { return false; }
void MpiTransport::SendControl(int, std::int64_t) {}
bool MpiTransport::PollControl(std::int64_t*) { return false; }
bool MpiTransport::AllOk(bool ok) { return ok; }
bool MpiTransport::RootOk(bool ok) { return ok; }
int MpiTransport::RootStatus(int status) { return status; }
void MpiTransport::Abort(int code) { std::exit(code); }

}  // namespace crowdrecon::sweep

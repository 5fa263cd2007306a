#include "mpi_distribution.hpp"

#include <atomic>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <exception>
#include <optional>
#include <stdexcept>
#include <thread>

#define OMPI_SKIP_MPICXX 1  // the C API only
#include <mpi.h>

#include <fmt/format.h>

namespace poundsim::apps {

namespace {

constexpr int kTaskTag = 1, kResultTag = 2, kEndTag = 3;

/// Launched by mpirun (Open MPI sets OMPI_COMM_WORLD_SIZE; PMI and PMIx launchers their own).
bool launched_by_mpirun() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"}) {
    if (std::getenv(name) != nullptr) return true;
  }
  return false;
}

void check(int code, const char* call) {
  if (code != MPI_SUCCESS) throw std::runtime_error(fmt::format("MPI: {} failed (error {})", call, code));
}

int byte_count(const std::string& bytes) {
  if (bytes.size() > static_cast<std::size_t>(INT_MAX)) {
    throw std::runtime_error(fmt::format("MPI: a message of {} bytes is larger than one send carries", bytes.size()));
  }
  return static_cast<int>(bytes.size());
}

void send(const std::string& bytes, int to, int tag) {
  check(MPI_Send(bytes.data(), byte_count(bytes), MPI_BYTE, to, tag, MPI_COMM_WORLD), "MPI_Send");
}

/// The message `status` announced (probed), received.
std::string receive(const MPI_Status& status) {
  int count = 0;
  check(MPI_Get_count(&status, MPI_BYTE, &count), "MPI_Get_count");
  std::string bytes(static_cast<std::size_t>(count), '\0');
  check(MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
        "MPI_Recv");
  return bytes;
}

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  if (!launched_by_mpirun()) return;
  int provided = 0;
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  active_ = true;
  if (provided < MPI_THREAD_FUNNELED) {
    fmt::print(stderr, "poundsim: error: MPI offers no thread support (MPI_THREAD_FUNNELED needed)\n");
    abort(1);
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiSession::~MpiSession() {
  if (active_) MPI_Finalize();
}

void MpiSession::abort(int code) const {
  if (active_) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

MpiDistribution::End MpiDistribution::serve(const std::function<std::string(const std::string&)>& compute) const {
  for (;;) {
    // Polled, not MPI_Probe: Open MPI spins a core in a blocking probe, and a worker may wait
    // long while rank 0 works alone (an optimiser between evaluations).
    MPI_Status status;
    int arrived = 0;
    while (arrived == 0) {
      check(MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &arrived, &status), "MPI_Iprobe");
      if (arrived == 0) std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
    const std::string message = receive(status);
    if (status.MPI_TAG == kEndTag) return message == "stopped" ? End::stopped : message == "finished" ? End::finished : End::done;
    send(compute(message), 0, kResultTag);
  }
}

void MpiDistribution::serve_until_finished(const std::function<std::string(const std::string&)>& compute) {
  if (rank_ == 0) return;
  while (serve(compute) != End::finished) {
  }
}

void MpiDistribution::finish() {
  if (rank_ != 0) return;
  for (int w = 1; w < size_; ++w) send("finished", w, kEndTag);
}

bool MpiDistribution::run_phase(const std::vector<std::string>& tasks,
                                const std::function<std::string(const std::string&)>& compute,
                                const std::function<void(std::size_t, const std::string&)>& store,
                                const std::function<bool()>& stop) {
  if (rank_ != 0) {
    const End end = serve(compute);
    if (end == End::finished) throw std::runtime_error("MPI: the coordinator finished in the middle of a phase");
    return end == End::stopped;
  }
  std::size_t next = 0;
  bool stopped = false;
  // Whether to hand out another task: none once the caller asked to stop (a stop asked once
  // every task is out stops nothing).
  const auto more = [&] {
    if (next >= tasks.size()) return false;
    if (!stopped && stop && stop()) stopped = true;
    return !stopped;
  };
  std::vector<std::size_t> held(static_cast<std::size_t>(size_));  // the task each worker computes
  int out = 0;  // tasks at the workers
  for (int w = 1; w < size_ && more(); ++w) {
    held[static_cast<std::size_t>(w)] = next;
    send(tasks[next++], w, kTaskTag);
    ++out;
  }
  // Rank 0's own share, on a thread of its own: the main thread keeps answering the workers.
  struct Own {
    std::size_t task = 0;
    std::thread thread;
    std::string result;
    std::exception_ptr error;
    std::atomic<bool> done{false};
  };
  std::optional<Own> own;
  const auto start_own = [&] {
    if (!more()) return;
    own.emplace();
    own->task = next++;
    own->thread = std::thread([&compute, &tasks, &own] {
      try {
        own->result = compute(tasks[own->task]);
      } catch (...) {
        own->error = std::current_exception();
      }
      own->done = true;
    });
  };
  try {
    start_own();
    while (out > 0 || own) {
      bool progressed = false;
      int arrived = 0;
      MPI_Status status;
      check(MPI_Iprobe(MPI_ANY_SOURCE, kResultTag, MPI_COMM_WORLD, &arrived, &status), "MPI_Iprobe");
      if (arrived != 0) {
        const std::string result = receive(status);
        const auto w = static_cast<std::size_t>(status.MPI_SOURCE);
        const std::size_t finished = held[w];
        --out;
        if (more()) {  // the next task goes out before this result is stored: the worker waits less
          held[w] = next;
          send(tasks[next++], status.MPI_SOURCE, kTaskTag);
          ++out;
        }
        store(finished, result);
        progressed = true;
      }
      if (own && own->done) {
        own->thread.join();
        if (own->error) std::rethrow_exception(own->error);
        const std::size_t task = own->task;
        const std::string result = std::move(own->result);
        own.reset();
        start_own();
        store(task, result);
        progressed = true;
      }
      if (!progressed) std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  } catch (...) {
    // A store or a message failed: the own thread must end before it is destroyed.
    if (own && own->thread.joinable()) own->thread.join();
    throw;
  }
  for (int w = 1; w < size_; ++w) send(stopped ? "stopped" : "done", w, kEndTag);
  return stopped;
}

}  // namespace poundsim::apps

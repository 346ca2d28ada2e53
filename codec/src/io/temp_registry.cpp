// Temporary files removed on SIGINT/SIGTERM/SIGHUP. The handler may only use
// async-signal-safe calls: the paths live in fixed buffers, unlink() removes them, then the
// signal's default action is restored and the signal raised again (so the exit status
// still says what killed the process).
#include "io/temp_registry.h"

#include <atomic>
#include <csignal>
#include <cstring>
#include <unistd.h>

#include <pomar/mesh_io.h>

namespace pomar {
namespace {

constexpr int kSlots = 8;
constexpr size_t kPathBytes = 4096;
char g_paths[kSlots][kPathBytes];
std::atomic<bool> g_used[kSlots];

extern "C" void remove_temporaries_and_reraise(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (g_used[i].load())
      ::unlink(g_paths[i]);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

} // namespace

int register_temporary(const std::string &path) {
  if (path.size() >= kPathBytes)
    return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_used[i].load() || !g_used[i].compare_exchange_strong(expected, true))
      continue;
    // Mark the slot unusable while the path is copied: an empty string unlinks nothing.
    g_paths[i][0] = '\0';
    std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
    return i;
  }
  return -1;
}

void unregister_temporary(int slot) {
  if (slot >= 0 && slot < kSlots)
    g_used[slot].store(false);
}

void remove_temporary_files_on_signals() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction action;
    std::memset(&action, 0, sizeof action);
    action.sa_handler = remove_temporaries_and_reraise;
    sigemptyset(&action.sa_mask);
    ::sigaction(sig, &action, nullptr);
  }
}

} // namespace pomar

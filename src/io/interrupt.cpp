// Ctrl-C, kill and a closed terminal leave no half-written output behind: every AtomicFile
// registers its temporary name here while it is open, and the handler of the interrupt signals
// unlinks the registered names (only async-signal-safe calls), says what happened and exits with
// code 130.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstring>

#include "g2s/error.hpp"
#include "g2s/io.hpp"
#include "io/temp_registry.hpp"

namespace g2s {
namespace {

constexpr int kSlots = 64;
constexpr std::size_t kPathMax = 4096;

struct Slot {
  std::atomic<bool> used{false};
  std::atomic<bool> ready{false};
  char path[kPathMax] = {};
};
// Zero bytes in .bss, set at compile time: an initialiser run at start-up would touch the 64 pages
// of the 256 KB, 64 page faults in every process (about 2 ms on the 2-vCPU VM).
constinit Slot g_slots[kSlots];

void on_signal(int) {
  for (Slot& s : g_slots) {
    if (s.ready.load(std::memory_order_acquire)) ::unlink(s.path);
  }
  static const char message[] = "g2s: interrupted; temporary files removed, no output written\n";
  [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, message, sizeof message - 1);
  ::_exit(static_cast<int>(Exit::interrupted));
}

}  // namespace

int register_temporary(const char* path) {
  if (std::strlen(path) >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_slots[i].used.compare_exchange_strong(expected, true)) {
      std::strcpy(g_slots[i].path, path);
      g_slots[i].ready.store(true, std::memory_order_release);
      return i;
    }
  }
  return -1;  // more than kSlots open at once: that one is not cleaned on a signal
}

void unregister_temporary(int slot) {
  if (slot < 0) return;
  g_slots[slot].ready.store(false, std::memory_order_release);
  g_slots[slot].used.store(false, std::memory_order_release);
}

std::span<const int> interrupt_signals() {
  static constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
  return kSignals;
}

void install_interrupt_cleanup() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  for (const int signal : interrupt_signals()) ::sigaction(signal, &action, nullptr);
}

}  // namespace g2s

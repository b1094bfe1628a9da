#include "delayspec/cancellation.hpp"

namespace delayspec {

namespace {
thread_local CancellationCheck* current_check = nullptr;
}

CancellationCheck* current_cancellation_check() noexcept { return current_check; }

CancellationScope::CancellationScope(CancellationCheck* check) noexcept : previous_(current_check) {
  current_check = check;
}

CancellationScope::~CancellationScope() { current_check = previous_; }

}  // namespace delayspec

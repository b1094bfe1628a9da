#include "delayspec/detail/remembered_trig.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>

namespace delayspec::detail {

__thread TrigSet* trig_sets[2] __attribute__((tls_model("initial-exec"))) = {nullptr, nullptr};

namespace {

// The table: 2^13 two-way sets per function. A miss moves entry 0 to 1 and stores the new pair
// in 0; a hit in entry 1 swaps them. With 2^13 sets the ~1300 distinct times a period of steps
// evaluates at N = 1000 (the step nodes l h and l h + h) are all kept: a key is lost only when
// three or more keys of one period share its set, probability ~ lambda^2 / 2 ~ 1 % at
// lambda = 1300 / 8192 keys per set. Keys compare by their bits, so -0.0 and +0.0 are different
// arguments and a value is always that of this argument. 256 KiB per function and thread.
//
// A new table is filled with one true entry, the argument +0.0 and its value, so there is no
// "empty" mark for an argument to collide with (the earlier memo marked empty entries with a
// NaN's bits and answered 0 for sin of that NaN).
template <Trig fn>
struct Table {
  TrigSet sets[std::size_t{1} << kTrigSetBits];
  Table() {
    const double v = fn == Trig::sin ? std::sin(0.0) : std::cos(0.0);
    for (TrigSet& s : sets) s.argument[0] = s.argument[1] = 0, s.value[0] = s.value[1] = v;
  }
};

// The owners of the thread's tables, freed at thread exit (trig_sets holds the raw pointers;
// the owner is a C++ thread_local with a destructor, touched only on a miss).
struct OwnedTables {
  std::unique_ptr<Table<Trig::sin>> sin;
  std::unique_ptr<Table<Trig::cos>> cos;
  ~OwnedTables() { trig_sets[0] = trig_sets[1] = nullptr; }
};
thread_local OwnedTables owned_tables;

TrigSet* create_table(Trig fn) {
  if (fn == Trig::sin) return (owned_tables.sin = std::make_unique<Table<Trig::sin>>())->sets;
  return (owned_tables.cos = std::make_unique<Table<Trig::cos>>())->sets;
}

}  // namespace

double remembered_trig_miss(Trig fn, double x) {
  const int which = static_cast<int>(fn);
  if (!trig_sets[which]) trig_sets[which] = create_table(fn);
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  TrigSet& s = trig_sets[which][trig_set_index(bits)];
  if (bits == s.argument[0]) return s.value[0];  // the thread's first call, or the inline lookup not made
  if (bits == s.argument[1]) {                   // a hit in the older entry: it becomes the newer
    std::swap(s.argument[0], s.argument[1]);
    std::swap(s.value[0], s.value[1]);
    return s.value[0];
  }
  const double v = fn == Trig::sin ? std::sin(x) : std::cos(x);
  s.argument[1] = s.argument[0];
  s.value[1] = s.value[0];
  s.argument[0] = bits;
  s.value[0] = v;
  return v;
}

}  // namespace delayspec::detail

// A firmware object on the heap as it is in a microcontroller's .bss: constructed in zeroed
// memory, so that every byte of it, the padding between its members too, has a defined value.
// The TMCM-3216 compares whole axis objects byte for byte to prove an axis at rest
// (Tmcm3216::run_axis_checking_rest); in memory `new` leaves as it was, their padding is
// indeterminate, and valgrind's memcheck rightly reports the comparison.
#pragma once

#include <cstring>
#include <memory>
#include <new>
#include <utility>

namespace motwin::host {

template <class T, class... Args>
std::unique_ptr<T> make_unique_zeroed(Args&&... args) {
  void* storage = ::operator new(sizeof(T));
  std::memset(storage, 0, sizeof(T));
  try {
    return std::unique_ptr<T>(::new (storage) T(std::forward<Args>(args)...));
  } catch (...) {
    ::operator delete(storage);
    throw;
  }
}

}  // namespace motwin::host

#include "common/time/utime.h"

#include <chrono>

namespace vimot {

int64_t wall_clock_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace vimot

// Runs a test scope on one OpenMP thread: tiny problems with many steps would otherwise spend their
// time in OpenMP barriers on a busy machine (results are bitwise the same for any thread count,
// tested in test_dynamics and test_kernel).
#pragma once
#include <omp.h>

namespace pdtest {

struct OneThread {
  int saved = omp_get_max_threads();
  OneThread() { omp_set_num_threads(1); }
  ~OneThread() { omp_set_num_threads(saved); }
  OneThread(const OneThread&) = delete;
  OneThread& operator=(const OneThread&) = delete;
};

}  // namespace pdtest

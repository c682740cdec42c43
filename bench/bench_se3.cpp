#include <benchmark/benchmark.h>

#include "scanmatch/core/se3.hpp"

static void BM_Se3ExpLog(benchmark::State& state) {
  scanmatch::Vector6d xi;
  xi << 0.1, -0.2, 0.3, 1.0, 2.0, 3.0;
  for (auto _ : state) {
    auto T = scanmatch::se3_exp(xi);
    benchmark::DoNotOptimize(xi = scanmatch::se3_log(T));
  }
}
BENCHMARK(BM_Se3ExpLog);

// The machine's memory bandwidth, STREAM style (McCalpin's copy and triad kernels), as the floor
// against which the steps' memory-bound phases are read (docs/benchmarks.md "Bandwidth"):
// BM_StreamCopy (c = a: 16 bytes an element) and BM_StreamTriad (a = b + s c: 24 bytes) on arrays
// of $MCFBENCH_STREAM_MB megabytes each (256 by default: far beyond any last-level cache), at 1, 2
// and all cores. The bytes counted are STREAM's: the write-allocate read of the destination is not
// counted, as STREAM does not, so the figures compare with published STREAM results.
// BM_PeakFlops is the compute side of the same yardstick: independent fused multiply-add chains
// held in registers (no memory traffic), at 1, 2 and all cores, reporting `flops_per_second` with
// a multiply-add counted as two flops, as the phases' floors count them.

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <thread>
#include <vector>

namespace {

std::size_t elements() {
  const char* mb = std::getenv("MCFBENCH_STREAM_MB");
  const std::size_t bytes = std::size_t(mb ? std::atof(mb) : 256.0) * 1024 * 1024;
  return std::max<std::size_t>(bytes / sizeof(double), 1024);
}

struct Arrays {
  std::vector<double> a, b, c;
  Arrays() : a(elements(), 1.0), b(elements(), 2.0), c(elements(), 0.0) {}
};

Arrays& arrays() {
  static Arrays arr;
  return arr;
}

// Each thread touches the same block on every pass (static partition), so pages stay on the
// thread's memory node as first touch placed them.
template <class Kernel>
void run(benchmark::State& state, double bytes_per_element, Kernel kernel) {
  const int threads =
      int(state.range(0)) > 0 ? int(state.range(0)) : int(std::thread::hardware_concurrency());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  Arrays& arr = arrays();
  const std::size_t n = arr.a.size();
  for (auto _ : state) {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, n / (8 * threads) + 1),
        [&](const tbb::blocked_range<std::size_t>& r) { kernel(arr, r.begin(), r.end()); },
        tbb::static_partitioner());
    benchmark::ClobberMemory();
  }
  state.counters["threads"] = threads;
  state.counters["bandwidth_GBps"] = benchmark::Counter(
      bytes_per_element * double(n) * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_StreamCopy(benchmark::State& state) {
  run(state, 16.0, [](Arrays& x, std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) x.c[i] = x.a[i];
  });
}

void BM_StreamTriad(benchmark::State& state) {
  run(state, 24.0, [](Arrays& x, std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) x.a[i] = x.b[i] + 3.0 * x.c[i];
  });
}

// Per thread, kChains accumulators x <- x a + b (std::fma: one instruction where the processor has
// it), enough independent chains to cover the FMA units' latency with vector registers; the
// compiler vectorizes the fixed-size inner loop and keeps it in registers.
void BM_PeakFlops(benchmark::State& state) {
  const int threads =
      int(state.range(0)) > 0 ? int(state.range(0)) : int(std::thread::hardware_concurrency());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  constexpr int kChains = 64;
  constexpr long kRounds = 1L << 22;
  std::vector<double> sums(std::size_t(threads), 0.0);
  for (auto _ : state) {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, threads, 1),
        [&](const tbb::blocked_range<int>& r) {
          for (int t = r.begin(); t < r.end(); ++t) {
            double x[kChains];
            for (int k = 0; k < kChains; ++k) x[k] = 1.0 + 1e-3 * k;
            const double a = 0.9999999, b = 1e-7;
            for (long i = 0; i < kRounds; ++i)
              for (int k = 0; k < kChains; ++k) x[k] = std::fma(x[k], a, b);
            double s = 0.0;
            for (int k = 0; k < kChains; ++k) s += x[k];
            sums[std::size_t(t)] = s;
          }
        },
        tbb::static_partitioner());
    benchmark::DoNotOptimize(sums.data());
  }
  state.counters["threads"] = threads;
  state.counters["flops_per_second"] = benchmark::Counter(
      2.0 * kChains * double(kRounds) * threads, benchmark::Counter::kIsIterationInvariantRate);
}

// 0 = all cores.
BENCHMARK(BM_StreamCopy)->Arg(1)->Arg(2)->Arg(0)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StreamTriad)->Arg(1)->Arg(2)->Arg(0)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PeakFlops)->Arg(1)->Arg(2)->Arg(0)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>
#include <thread>
#include <vector>

namespace subscan {

/// Runs `work(i)` for every i < count, split across the machine's cores (at most 16) in
/// contiguous ranges.
template <class Work>
void inParallel(std::size_t count, const Work& work) {
    const std::size_t threads = std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, 16);
    const auto range = [&](std::size_t thread) {
        const std::size_t last = (thread + 1) * count / threads;
        for (std::size_t i = thread * count / threads; i < last; ++i) {
            work(i);
        }
    };
    std::vector<std::jthread> workers;
    for (std::size_t thread = 1; thread < threads; ++thread) {
        workers.emplace_back(range, thread);
    }
    range(0);
}

/// Runs `work(i)` for every i < count, split across the machine's cores (at most 16) in blocks
/// of `block` consecutive indices that each thread takes as it finishes the last: a thread the
/// system slows down (another process on its core) delays one block, not half of the work.
template <class Work>
void inParallelBlocks(std::size_t count, std::size_t block, const Work& work) {
    const std::size_t threads = std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, 16);
    std::atomic<std::size_t> next{0};
    const auto take = [&] {
        for (std::size_t first = next.fetch_add(block); first < count;
             first = next.fetch_add(block)) {
            const std::size_t last = std::min(first + block, count);
            for (std::size_t i = first; i < last; ++i) {
                work(i);
            }
        }
    };
    std::vector<std::jthread> workers;
    for (std::size_t thread = 1; thread < threads; ++thread) {
        workers.emplace_back(take);
    }
    take();
}

/// inParallelBlocks that stops once `cancelled` (may be empty) says yes: asked, from any thread,
/// every 16,384 indices, so that a caller waiting on it (a job being dropped) waits little.
/// Returns whether it stopped; the work is then incomplete.
template <class Work>
bool inParallelBlocksUntil(std::size_t count, std::size_t block,
                           const std::function<bool()>& cancelled, const Work& work) {
    constexpr std::size_t kCancelCheckEvery = 1 << 14;
    std::atomic<bool> stopped{false};
    inParallelBlocks(count, block, [&](std::size_t i) {
        if (cancelled && (stopped.load(std::memory_order_relaxed) ||
                          (i % kCancelCheckEvery == 0 && cancelled()))) {
            stopped.store(true, std::memory_order_relaxed);
            return;
        }
        work(i);
    });
    return stopped;
}

}  // namespace subscan

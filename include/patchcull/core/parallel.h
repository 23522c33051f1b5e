// patchcull/core/parallel.h: multi-core execution of kernels over patch ranges (oneTBB underneath).
#pragma once

#include <cstddef>
#include <type_traits>
#include <utility>

namespace patchcull {

/// A non-owning reference to a callable body(first, last): passing a lambda allocates nothing.
/// The callable must outlive the call it is passed to (a temporary lambda argument does).
class RangeBody {
public:
    template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, RangeBody>>>
    RangeBody(F&& f)  // NOLINT(google-explicit-constructor): a lambda converts implicitly
        : object_(const_cast<void*>(static_cast<const void*>(&f))),
          call_([](void* o, std::size_t first, std::size_t last) {
              (*static_cast<std::remove_reference_t<F>*>(o))(first, last);
          }) {}
    void operator()(std::size_t first, std::size_t last) const { call_(object_, first, last); }

private:
    void* object_;
    void (*call_)(void*, std::size_t, std::size_t);
};

/// Calls body(first, last) over disjoint ranges covering [0, count), in parallel on the calling
/// thread and oneTBB's workers. Range starts are multiples of grain (grain a multiple of 16 keeps
/// SIMD loads aligned in batches; 0 counts as 1). Allocates nothing of its own per call (oneTBB's
/// task objects come from its own pools).
void parallel_for_ranges(std::size_t count, std::size_t grain, RangeBody body);

/// Number of worker threads parallel_for_ranges may use.
int hardware_threads();

}  // namespace patchcull

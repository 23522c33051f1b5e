// Internal (src/import only): asks the kernel to back a large buffer with huge pages.
//
// Why: preprocessing a 1M-quad mesh writes ~1 GB of fresh stencils and patches once. With 4 KB
// pages that is ~250,000 page faults, which cost more than the arithmetic (measured: over a third
// of `patchcull info` on a virtual machine); with transparent huge pages in "madvise"
// mode (Debian's default) a 2 MB page takes one fault. Only advice: where the kernel has no
// huge pages, or on other systems, nothing changes, and no result ever depends on it.
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace patchcull::detail {

/// Advises huge pages for the whole 2 MB pages inside [data, data + bytes); buffers under 4 MB
/// are left alone (a huge page there would mostly hold other allocations' memory).
inline void advise_huge_pages(void* data, std::size_t bytes) {
#if defined(MADV_HUGEPAGE)
    constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
    if (!data || bytes < 2 * kHuge) return;
    const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
    const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kHuge - 1);
    // An address computed from the allocation's own. NOLINTNEXTLINE(performance-no-int-to-ptr)
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
    (void)data;
    (void)bytes;
#endif
}

}  // namespace patchcull::detail

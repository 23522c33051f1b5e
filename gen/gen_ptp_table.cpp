// patchcull_gen_ptp_table: writes Loop, Niessner & Eisenacher's parametric tangent plane table
// (src/core/ptp_table.inc) to stdout, derived from the definition in exact rational arithmetic
// (src/core/ptp_table_gen.cpp), and a summary (term count, per-destination matrix, degree
// reduction) to stderr.
//
//   patchcull_gen_ptp_table > src/core/ptp_table.inc
#include <cstdio>
#include <exception>
#include <iostream>

#include "core/ptp_table_gen.h"

int main() {
    using namespace patchcull::ptp_gen;
    try {
        const Expansion e = expand_ptp();
        const std::vector<Term> ordered = order_for_16_lanes(e.terms);
        std::cout << table_inc_text(ordered);
        std::fprintf(stderr, "non-zero sorted triples: %d, terms: %zu, exact reduction 8 -> 7: %s\n",
                     e.triples_considered, e.terms.size(), e.reduced_exactly ? "yes" : "NO");
        const std::vector<int> m = terms_per_destination(e.terms);
        for (int jv = 0; jv < 8; ++jv) {
            for (int iu = 0; iu < 8; ++iu) std::fprintf(stderr, " %2d", m[8 * jv + iu]);
            std::fprintf(stderr, "\n");
        }
        return 0;
    } catch (const std::exception& ex) {
        std::fprintf(stderr, "patchcull_gen_ptp_table: %s\n", ex.what());
        return 1;
    }
}

// Scheme dispatch, stencil tables and per-frame patch evaluation (patchcull/import/subdivision.h).
#include "patchcull/import/subdivision.h"

#include <algorithm>
#include <string>

#include "import/huge_pages.h"
#include "patchcull/core/error.h"
#include "patchcull/core/parallel.h"

namespace patchcull {

const char* scheme_name(Scheme scheme) { return scheme == Scheme::acc ? "acc" : "osd"; }

bool parse_scheme(const std::string& text, Scheme& scheme) {
    if (text == "acc")
        scheme = Scheme::acc;
    else if (text == "osd")
        scheme = Scheme::osd;
    else
        return false;
    return true;
}

void PointStencils::add_row(const std::vector<std::pair<std::uint32_t, float>>& terms) {
    // Rows that come sorted without duplicates (Far's and the acc rows are) are appended as they
    // are; others take a sorted merge (O(k log k), no per-row node allocations: rows next to a
    // high-valence vertex have hundreds of terms). Both sum each weight as 0.0f + w, so either
    // path stores the same bits.
    const bool sorted_unique = std::adjacent_find(terms.begin(), terms.end(), [](const auto& a, const auto& b) {
                                   return a.first >= b.first;
                               }) == terms.end();
    if (sorted_unique) {
        for (const auto& [index, w] : terms) {
            const float weight = 0.0f + w;
            if (weight == 0.0f) continue;
            indices.push_back(index);
            weights.push_back(weight);
        }
        offsets.push_back(static_cast<std::uint32_t>(indices.size()));
        return;
    }
    thread_local std::vector<std::pair<std::uint32_t, float>> sorted;
    sorted.assign(terms.begin(), terms.end());
    std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t k = 0; k < sorted.size();) {
        const std::uint32_t index = sorted[k].first;
        float weight = 0.0f;
        for (; k < sorted.size() && sorted[k].first == index; ++k) weight += sorted[k].second;
        if (weight == 0.0f) continue;
        indices.push_back(index);
        weights.push_back(weight);
    }
    offsets.push_back(static_cast<std::uint32_t>(indices.size()));
}

namespace {

// Row r of a stencil table applied to vertices (double accumulation: extraordinary stencils have
// dozens of terms of both signs).
inline Vec3 apply_row(const PointStencils& s, std::size_t r, const Vec3* vertices) {
    double x = 0, y = 0, z = 0;
    for (std::uint32_t k = s.offsets[r]; k < s.offsets[r + 1]; ++k) {
        const Vec3 v = vertices[s.indices[k]];
        const double w = s.weights[k];
        x += w * v.x;
        y += w * v.y;
        z += w * v.z;
    }
    return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
}

// Patches per task of evaluate_patches (~100 us each).
constexpr std::size_t kEvaluateGrain = 1024;

}  // namespace

void PointStencils::apply(const Vec3* vertices, Vec3* out) const {
    const std::size_t n = rows();
    for (std::size_t r = 0; r < n; ++r) out[r] = apply_row(*this, r, vertices);
}

std::size_t SubdivisionModel::extraordinary_count() const {
    return static_cast<std::size_t>(
        std::count_if(patches.begin(), patches.end(), [](const PatchInfo& p) { return p.extraordinary; }));
}

void check_preprocessing_limits(const ControlMesh& mesh) {
    const std::size_t nf = mesh.face_count();
    for (std::size_t f = 0; f < nf; ++f)
        if (mesh.face_size(f) > kMaxFaceCorners)
            throw Error(mesh.name + ": face " + std::to_string(f + 1) + " has " + std::to_string(mesh.face_size(f)) +
                        " corners; patchcull takes faces of at most " + std::to_string(kMaxFaceCorners) +
                        " corners (preprocessing costs ~n^2 in a face's corner count n)");
    std::vector<std::uint32_t> valence(mesh.positions.size(), 0);
    for (const std::uint32_t v : mesh.face_vertices)
        if (v < valence.size() && ++valence[v] > kMaxValence) {
            // Report the vertex with its full valence.
            std::uint32_t n = 0;
            for (const std::uint32_t w : mesh.face_vertices) n += w == v;
            throw Error(mesh.name + ": vertex " + std::to_string(std::uint64_t{v} + 1) + " has valence " +
                        std::to_string(n) + " (faces around it); patchcull takes vertices of valence at most " +
                        std::to_string(kMaxValence) + " (preprocessing costs ~n^2 in a vertex's valence n)");
        }
}

SubdivisionModel build_model(const ControlMesh& mesh, Scheme scheme) {
    if (mesh.face_count() == 0) throw Error(mesh.name + ": mesh has no faces");
    check_preprocessing_limits(mesh);
    return scheme == Scheme::acc ? build_acc_model(mesh) : build_osd_model(mesh);
}

namespace {

// One uniform 1-to-4 split of a whole frame.
void split_frame(const PatchFrame& in, PatchFrame& out) {
    out.patches.resize(in.patches.size() * 4);
    out.info.resize(in.info.size() * 4);
    out.tangents.resize(in.tangents.size() * 4);
    for (std::size_t p = 0; p < in.patches.size(); ++p) {
        split_patch(in.patches[p], &out.patches[4 * p]);
        const PatchInfo& parent = in.info[p];
        // Children in split_patch order: (u low, v low), (u high, v low), (u low, v high), (u high, v high).
        for (int c = 0; c < 4; ++c) {
            const float u0 = (c & 1) ? 0.5f : 0.0f;
            const float v0 = (c & 2) ? 0.5f : 0.0f;
            PatchInfo child = parent;
            for (int k = 0; k < 4; ++k) {
                const float u = u0 + ((k & 1) ? 0.5f : 0.0f);
                const float v = v0 + ((k & 2) ? 0.5f : 0.0f);
                const Vec2 bottom = parent.uv[0] * (1 - u) + parent.uv[1] * u;
                const Vec2 top = parent.uv[2] * (1 - u) + parent.uv[3] * u;
                child.uv[k] = bottom * (1 - v) + top * v;
            }
            child.tangent_index = parent.tangent_index < 0 ? -1 : 4 * parent.tangent_index + c;
            out.info[4 * p + c] = child;
        }
    }
    for (std::size_t t = 0; t < in.tangents.size(); ++t) split_tangents(in.tangents[t], &out.tangents[4 * t]);
}

}  // namespace

void evaluate_patches(const SubdivisionModel& model, const std::vector<Vec3>& positions, int split_levels,
                      PatchFrame& out) {
    // Straight into the frame (no array of all points in between: 192 MB at 1M patches), in
    // parallel: every control point is its own row, so the result does not depend on the split.
    const std::size_t n = model.patch_count();
    if (model.patch_points.rows() < n * kPatchPoints)
        throw Error(model.name + ": stencil table has fewer rows than its patches need");
    if (out.patches.capacity() < n) {
        out.patches = {};
        out.patches.reserve(n);
        detail::advise_huge_pages(out.patches.data(), n * sizeof(BezierPatch));
    }
    out.patches.resize(n);
    const std::size_t nt = model.tangent_points.rows() / 24;
    out.tangents.resize(nt);
    const Vec3* vertices = positions.data();
    parallel_for_ranges(n, kEvaluateGrain, [&](std::size_t first, std::size_t last) {
        for (std::size_t p = first; p < last; ++p)
            for (int k = 0; k < kPatchPoints; ++k)
                out.patches[p].cp[k] = homogeneous(apply_row(model.patch_points, kPatchPoints * p + k, vertices));
    });
    parallel_for_ranges(nt, kEvaluateGrain, [&](std::size_t first, std::size_t last) {
        for (std::size_t t = first; t < last; ++t)
            for (int k = 0; k < 12; ++k) {
                out.tangents[t].du[k] = apply_row(model.tangent_points, 24 * t + k, vertices);
                out.tangents[t].dv[k] = apply_row(model.tangent_points, 24 * t + 12 + k, vertices);
            }
    });
    out.info = model.patches;

    PatchFrame scratch;
    for (int level = 0; level < split_levels; ++level) {
        split_frame(out, scratch);
        std::swap(out, scratch);
    }
}

}  // namespace patchcull

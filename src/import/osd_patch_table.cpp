// An OpenSubdiv Far::PatchTable as patch sources over the caller's vertex buffer
// (patchcull/import/osd_patch_table.h).
//
// Facts about Far used here (OpenSubdiv 3.5, far/patchTable.h, far/patchParam.h,
// far/patchBasis.cpp): the arrays' patches are numbered consecutively in array order (an
// array's first patch index is the sum of the earlier arrays' counts), and its control-vertex
// indices are one contiguous run (GetPatchArrayVertices); PatchParam::GetBoundary() is a 5-bit
// field of which a quad patch uses the low 4 (bit 0 the edge t = 0, 1 s = 1, 2 t = 1, 3 s = 0),
// and EvaluateBasis applies it to every REGULAR patch, end caps included, whatever IsRegular()
// says; GREGORY_BASIS patches have no boundary extrapolation.
#include "patchcull/import/osd_patch_table.h"

#include <algorithm>
#include <string>
#include <type_traits>

#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTable.h>

#include "import/osd_topology.h"
#include "patchcull/core/error.h"

namespace patchcull {

namespace {

namespace Far = OpenSubdiv::Far;

constexpr bool kIndexIsViewable = std::is_same_v<std::make_unsigned_t<Far::Index>, std::uint32_t>;

// Runs body(array source, array's first patch) for every array, after checking them all.
template <class Body>
void for_each_array(const OsdPatchTableSource& table, const char* what, const Body& body) {
    for (const OsdPatchArraySource& a : table.arrays()) check_patch_source(a.source, what);
    for (const OsdPatchArraySource& a : table.arrays()) body(a.source, a.first_patch);
}

}  // namespace

std::string osd_patch_type_name(Far::PatchDescriptor::Type type) {
    switch (type) {
        case Far::PatchDescriptor::NON_PATCH:
            return "NON_PATCH";
        case Far::PatchDescriptor::POINTS:
            return "POINTS";
        case Far::PatchDescriptor::LINES:
            return "LINES";
        case Far::PatchDescriptor::QUADS:
            return "QUADS";
        case Far::PatchDescriptor::TRIANGLES:
            return "TRIANGLES";
        case Far::PatchDescriptor::LOOP:
            return "LOOP";
        case Far::PatchDescriptor::REGULAR:
            return "REGULAR";
        case Far::PatchDescriptor::GREGORY:
            return "GREGORY";
        case Far::PatchDescriptor::GREGORY_BOUNDARY:
            return "GREGORY_BOUNDARY";
        case Far::PatchDescriptor::GREGORY_BASIS:
            return "GREGORY_BASIS";
        case Far::PatchDescriptor::GREGORY_TRIANGLE:
            return "GREGORY_TRIANGLE";
    }
    return "type " + std::to_string(static_cast<int>(type));
}

OsdPatchTableSource::OsdPatchTableSource(const Far::PatchTable& table, const PointLayout& points) {
    static_assert(sizeof(Far::Index) == sizeof(std::uint32_t) || !kIndexIsViewable);
    const int array_count = table.GetNumPatchArrays();
    patch_count_ = static_cast<std::size_t>(table.GetNumPatchesTotal());
    masks_.assign(patch_count_, 0);
    std::size_t first = 0;
    std::size_t total_indices = 0;
    for (int a = 0; a < array_count; ++a) {
        const Far::PatchDescriptor desc = table.GetPatchArrayDescriptor(a);
        const Far::PatchDescriptor::Type type = desc.GetType();
        const int per_patch = desc.GetNumControlVertices();
        const int count = table.GetNumPatches(a);
        const bool regular = type == Far::PatchDescriptor::REGULAR && per_patch == 16;
        const bool gregory = type == Far::PatchDescriptor::GREGORY_BASIS && per_patch == 20;
        if (!regular && !gregory)
            throw Error("OsdPatchTableSource: patch array " + std::to_string(a) + " holds " + std::to_string(count) +
                        " patches of type " + osd_patch_type_name(type) + " (" + std::to_string(per_patch) +
                        " points); only REGULAR (16-point B-spline) and GREGORY_BASIS (20-point) patches can be "
                        "culled: build the table adaptively, with ENDCAP_GREGORY_BASIS or ENDCAP_BSPLINE_BASIS");
        OsdPatchArraySource out;
        out.array = a;
        out.first_patch = first;
        out.source.count = static_cast<std::size_t>(count);
        out.source.basis = regular ? PatchBasis::bspline : PatchBasis::gregory;
        const Far::ConstIndexArray cvs = table.GetPatchArrayVertices(a);
        const Far::ConstPatchParamArray params = table.GetPatchParams(a);
        bool any_boundary = false;
        for (int p = 0; p < count; ++p) {
            const unsigned mask = regular ? params[p].GetBoundary() : 0u;
            if (mask >= 16)
                throw Error("OsdPatchTableSource: patch " + std::to_string(first + static_cast<std::size_t>(p)) +
                            " (array " + std::to_string(a) + ", patch " + std::to_string(p) + ") has boundary mask " +
                            std::to_string(mask) + ", beyond a quad's 4 edges");
            masks_[first + static_cast<std::size_t>(p)] = static_cast<std::uint8_t>(mask);
            any_boundary = any_boundary || mask != 0;
            const std::uint32_t read = regular ? bspline_real_slots(mask) : ~0u;
            for (int k = 0; k < per_patch; ++k) {
                if (!((read >> k) & 1u)) continue;
                const Far::Index index = cvs[p * per_patch + k];
                if (index < 0)
                    throw Error("OsdPatchTableSource: patch " + std::to_string(first + static_cast<std::size_t>(p)) +
                                " (array " + std::to_string(a) + ", patch " + std::to_string(p) + "), point " +
                                std::to_string(k) + ": index " + std::to_string(index) + " is negative");
                points_needed_ = std::max(points_needed_, static_cast<std::size_t>(index) + 1);
            }
        }
        if (any_boundary) out.source.boundary_mask = masks_.data() + first;
        total_indices += static_cast<std::size_t>(count) * static_cast<std::size_t>(per_patch);
        arrays_.push_back(out);
        first += static_cast<std::size_t>(count);
    }
    if (first != patch_count_)
        throw Error("OsdPatchTableSource: the arrays hold " + std::to_string(first) + " patches, but the table has " +
                    std::to_string(patch_count_));
    // The index arrays: the table's own memory (int read as unsigned int, its unsigned
    // counterpart, which may alias it), or one conversion here.
    if constexpr (!kIndexIsViewable) indices_.reserve(total_indices);
    for (OsdPatchArraySource& out : arrays_) {
        const Far::ConstIndexArray cvs = table.GetPatchArrayVertices(out.array);
        if constexpr (kIndexIsViewable) {
            out.source.indices = cvs.size() > 0 ? reinterpret_cast<const std::uint32_t*>(&cvs[0]) : nullptr;
        } else {
            out.source.indices = indices_.data() + indices_.size();  // reserved: no reallocation
            for (int k = 0; k < cvs.size(); ++k) indices_.push_back(static_cast<std::uint32_t>(cvs[k]));
        }
    }
    bind_points(points);
}

void OsdPatchTableSource::bind_points(const PointLayout& points) {
    for (OsdPatchArraySource& a : arrays_) a.source.points = points;
}

void cull_frustum(const OsdPatchTableSource& table, const float* max_displacement, const CullView& view,
                  std::uint8_t* culled) {
    for_each_array(table, "cull_frustum", [&](const PatchSourceView& s, std::size_t first) {
        cull_frustum(s, max_displacement ? max_displacement + first : nullptr, view, culled + first);
    });
}

void cull_backpatch(BackpatchMethod id, const OsdPatchTableSource& table, const CullView& view,
                    const BackpatchOptions& options, std::uint8_t* culled) {
    (void)backpatch_method_info(id);  // an unknown id throws before any array is culled
    for_each_array(table, "cull_backpatch", [&](const PatchSourceView& s, std::size_t first) {
        cull_backpatch(id, s, view, options, culled + first);
    });
}

void cull_occlusion(const OsdPatchTableSource& table, const CullView& view, const HiZPyramid& hiz,
                    std::uint8_t* decision) {
    check_hiz_convention(hiz, view.depth, "cull_occlusion");
    for_each_array(table, "cull_occlusion", [&](const PatchSourceView& s, std::size_t first) {
        cull_occlusion(s, view, hiz, decision + first);
    });
}

void cull_frustum_disp(const OsdPatchTableSource& table, const float* max_displacement, const CullView& view,
                       std::uint8_t* culled) {
    check_clip_depth(view.object_to_clip, view.depth, "cull_frustum_disp");
    for_each_array(table, "cull_frustum_disp", [&](const PatchSourceView& s, std::size_t first) {
        cull_frustum_disp(s, max_displacement ? max_displacement + first : nullptr, view, culled + first);
    });
}

void cull_fused(const OsdPatchTableSource& table, const FusedCullSetup& setup, const FusedPlan& plan,
                std::uint8_t* decision, FusedCullStats* stats) {
    // The plan and the pyramid: the first array's entry checks them before it writes anything, and
    // every array's are the same.
    for_each_array(table, "cull_fused", [&](const PatchSourceView& s, std::size_t first) {
        cull_fused(s, setup, plan, decision + first, stats);
    });
}

namespace {

// A point for Far's primvar refinement and stencils (float, as the buffer an engine draws).
struct RefinePoint {
    float x = 0, y = 0, z = 0;
    void Clear(void* = nullptr) { x = y = z = 0; }
    void AddWithWeight(const RefinePoint& p, float w) {
        x += w * p.x;
        y += w * p.y;
        z += w * p.z;
    }
};

}  // namespace

OsdAdaptiveTable make_osd_adaptive_table(const ControlMesh& mesh, int isolation_level, bool bspline_end_caps) {
    if (isolation_level < 1 || isolation_level > 10)
        throw Error(mesh.name + ": isolation level " + std::to_string(isolation_level) + " is not in 1..10");
    osd_detail::RefinerPtr refiner = osd_detail::create_refiner(mesh);
    Far::PatchTableFactory::Options options(static_cast<unsigned>(isolation_level));
    options.SetEndCapType(bspline_end_caps ? Far::PatchTableFactory::Options::ENDCAP_BSPLINE_BASIS
                                           : Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    refiner->RefineAdaptive(options.GetRefineAdaptiveOptions());
    OsdAdaptiveTable out;
    out.table.reset(Far::PatchTableFactory::Create(*refiner, options));
    if (!out.table) throw Error(mesh.name + ": OpenSubdiv built no patch table");

    const int refined = refiner->GetNumVerticesTotal();
    std::vector<RefinePoint> all(static_cast<std::size_t>(refined + out.table->GetNumLocalPoints()));
    for (std::size_t v = 0; v < mesh.positions.size(); ++v)
        all[v] = {mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z};
    Far::PrimvarRefinerReal<float> primvar(*refiner);
    RefinePoint* src = all.data();
    for (int l = 1; l <= refiner->GetMaxLevel(); ++l) {
        RefinePoint* dst = src + refiner->GetLevel(l - 1).GetNumVertices();
        primvar.Interpolate(l, src, dst);
        src = dst;
    }
    if (const Far::StencilTable* local = out.table->GetLocalPointStencilTable())
        local->UpdateValues(all.data(), all.data() + refined);
    out.points.reserve(all.size());
    for (const RefinePoint& p : all) out.points.push_back({p.x, p.y, p.z});
    return out;
}

}  // namespace patchcull

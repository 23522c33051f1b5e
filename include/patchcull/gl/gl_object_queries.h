// patchcull/gl/gl_object_queries.h: object-level occlusion culling with hardware occlusion queries
// (library patchcull_gl), following G. Zachmann's lecture "Advanced Visibility Computations"
// (occlusion queries, the naive stop-and-wait loop, CHC and CHC++), Bittner, Wimmer,
// Piringer & Purgathofer, "Coherent Hierarchical Culling: Hardware Occlusion Queries Made
// Useful" (Eurographics 2004), and Mattausch, Bittner & Wimmer, "CHC++: Coherent Hierarchical
// Culling Revisited" (Eurographics 2008).
//
// An ObjectQueries is a CullPipeline ObjectPass (gl_pipeline.h): inside the frame, after the
// clear and the occluders, it draws the objects it finds visible and leaves out the others. A
// query draws an object's proxy (its box, or CHC++'s tight boxes) with depth test GL_LEQUAL and
// no writes against the depth drawn so far; the object is drawn when the query passes samples.
// Methods:
//   stop-and-wait  the baseline: objects sorted front to back (nearest box point), each queried
//                  and waited for, drawn when visible;
//   batched        the same order, queries issued b at a time, then their results read and the
//                  visible objects drawn;
//   chc            CHC over an ObjectBvh of the objects (each BVH leaf's objects its children):
//                  front-to-back traversal, the query queue processed as results arrive,
//                  previously visible objects drawn at once, visibility pulled up the tree,
//                  previously visible inner nodes opened without a query;
//   chc++          CHC with the I-queue (queries of previously invisible nodes issued b at a time,
//                  as multiqueries chosen greedily), the V-queue (queries of previously visible
//                  objects issued when the CPU would wait, read at the end of the frame), those
//                  queries skipped for visible_interval - 1 frames of n (random phase), and
//                  tight bounding volumes.
// Multiqueries (CHC++): the I-queue's nodes sorted by how long they were hidden (t), the first n
// of them queried with one query, n maximising V(M) = B(M) / C(M) with C(M) = 1 + c1 |M|,
// B(M) = i(M) * sum of their patches, i(M) = prod p(t_O), p(t) = 0.99 - 0.7 e^-t (the lecture's
// fit of the visibility persistence); a multiquery that passes samples is re-issued object by
// object (node by node).
//
// Conservative (pixel_threshold 0): an object is left out only when it is outside the frustum
// (its box, classify_aabb) or when a query on a box holding it (its own, a tight set whose union
// holds it, an ancestor's or a multiquery's) passed no sample against a depth buffer holding only
// what the frame draws anyway. Later draws only bring depth nearer, so the object is hidden in
// the final image too. The caller gives boxes holding everything each object draws; each is
// widened here (kQueryBoxMargin of its diagonal, plus the depth buffer's resolution at its far
// distance) so that rasterisation ties and depth rounding favour the proxy, and a box reaching
// in front of the near plane is never queried (clipped, its proxy could miss pixels): it counts
// as visible. pixel_threshold > 0 is the lecture's aggressive approximate culling: an object
// whose query passes at most that many samples is left out too; never conservative (render
// --verify reports the pixels it changes).
//
// Queries use GL_ANY_SAMPLES_PASSED_CONSERVATIVE (core since 4.3) with pixel_threshold 0, else
// GL_SAMPLES_PASSED (QueryOptions::any_samples false forces it). Threads and errors as
// gl_renderer.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/core/mesh.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/gl/gl_renderer.h"

namespace patchcull::gl {

/// A query box is widened by this fraction of its diagonal on every side (plus the depth
/// buffer's resolution at its far distance): ties at its silhouette and its depth rounding go
/// to the proxy.
inline constexpr float kQueryBoxMargin = 1e-3f;

enum class QueryMethod : std::uint8_t { stop_and_wait, batched, chc, chcpp };
/// "stop-and-wait", "batched", "chc", "chc++".
const char* query_method_name(QueryMethod method);
/// Parses query_method_name's names; false (method unchanged) otherwise.
bool parse_query_method(const std::string& text, QueryMethod& method);

struct QueryOptions {
    QueryMethod method = QueryMethod::chcpp;
    /// stop-and-wait and batched: objects sorted by their nearest box point (false: in order).
    bool front_to_back = true;
    /// b: batched's batch and CHC++'s I-queue size (>= 1).
    unsigned batch_size = 16;
    bool multiqueries = true;  ///< CHC++: the I-queue issued as multiqueries
    bool tight_bounds = true;  ///< CHC++: objects queried with their tight boxes (FrameObjects)
    /// CHC++: a previously visible object is queried every visible_interval frames (its phase
    /// random), assumed visible in between (>= 1; 1: every frame).
    unsigned visible_interval = 1;
    /// CHC++ multiquery cost per object over the cost of a query: C(M) = 1 + c1 |M|.
    float c1 = 0.1f;
    /// Aggressive approximate culling: visible only above this many samples (0: conservative).
    std::uint32_t pixel_threshold = 0;
    /// GL_ANY_SAMPLES_PASSED_CONSERVATIVE when pixel_threshold is 0; false: GL_SAMPLES_PASSED.
    bool any_samples = true;
    std::uint64_t seed = 1;  ///< CHC++'s random phases
};

/// What one frame of queries did.
struct QueryStats {
    std::uint32_t objects = 0;
    std::uint32_t frustum_culled = 0;     ///< objects outside the frustum (their box, or an ancestor's)
    std::uint32_t occlusion_culled = 0;   ///< objects left out by a query (conservative ones)
    std::uint32_t drawn = 0;              ///< objects drawn
    std::uint32_t queries = 0;            ///< query objects issued (a multiquery counts once)
    std::uint32_t multiqueries = 0;       ///< of queries: over more than one node
    std::uint32_t multiquery_passed = 0;  ///< multiqueries that passed samples (re-issued singly)
    std::uint32_t proxy_boxes = 0;        ///< boxes drawn under queries
    std::uint32_t waits = 0;              ///< results read before they were available (the CPU stalled)
    std::uint32_t unqueryable = 0;        ///< boxes reaching in front of the near plane (counted visible)
};

/// The objects of one frame (object order = PipelineParams::objects' order).
struct FrameObjects {
    Mat4 world_to_clip;                        ///< projection * view, in the renderer's clip depth convention
    ClipDepth depth = ClipDepth::zero_to_one;  ///< world_to_clip's convention (RenderParams::depth)
    Vec3 eye;                                  ///< world space
    /// World box of each object, holding everything it draws this frame.
    const Bounds* boxes = nullptr;
    std::size_t count = 0;
    /// Per object, the patches it draws (CHC++'s benefit); null: 1 each.
    const std::uint32_t* patches = nullptr;
    /// CHC++ tight bounding volumes: object i's boxes are tight[tight_first[i] .. tight_first[i+1])
    /// (each set's union holds everything the object draws; TightBounds::select); null: none.
    const Bounds* tight = nullptr;
    const std::uint32_t* tight_first = nullptr;
};

class ObjectQueries final : public ObjectPass {
public:
    /// Compiles the proxy program on ctx (made current).
    explicit ObjectQueries(const GlContext& ctx);
    /// The same on the OpenGL 4.5 context current on the calling thread (an engine's own).
    ObjectQueries();
    ObjectQueries(ObjectQueries&&) noexcept;
    ObjectQueries& operator=(ObjectQueries&&) noexcept;
    ObjectQueries(const ObjectQueries&) = delete;
    ObjectQueries& operator=(const ObjectQueries&) = delete;
    ~ObjectQueries() override;

    /// The next frame's objects and options (copied; call before CullPipeline::render_frame).
    /// A new object count (or the first call) builds the BVH and forgets visibility; otherwise
    /// the BVH is refitted. Throws patchcull::Error for batch_size or visible_interval 0, a null
    /// boxes with count > 0, or tight_first not ascending.
    void set_frame(const FrameObjects& frame, const QueryOptions& options);
    /// ObjectPass: the frame's queries and draws.
    void run(ObjectDrawer& drawer) override;
    /// Forgets the visibility of earlier frames (the next frame queries as a first frame).
    void reset();

    const QueryStats& stats() const;
    /// Per object after run: 1 drawn, 0 left out.
    const std::vector<std::uint8_t>& drawn() const;

private:
    struct Current {};
    explicit ObjectQueries(Current);
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace patchcull::gl

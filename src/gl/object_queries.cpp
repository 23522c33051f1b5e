// ObjectQueries (patchcull/gl/gl_object_queries.h): hardware occlusion queries, stop-and-wait,
// batched, CHC and CHC++, as a CullPipeline ObjectPass.
//
// The tree of CHC: the ObjectBvh's nodes 0 .. N-1, then the objects N .. N+n-1 as leaves (a BVH
// leaf's children are its objects), so that objects are queried and drawn one by one. Per tree
// node the history of CHC: visible last time it was visited, the frame of that visit, and how
// many consecutive visits found it hidden (CHC++'s t). No history decides a cull by itself: a
// node is left out only by a query of this frame (or the frustum), the history only chooses
// which nodes are drawn before their query returns (previously visible ones) and how queries are
// grouped (multiqueries).
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <queue>
#include <random>

#include "gl_util.h"
#include "patchcull/core/error.h"
#include "patchcull/core/frustum.h"
#include "patchcull/gl/gl_object_queries.h"
#include "patchcull/objects/bounding_volumes.h"
#include "patchcull/objects/object_bvh.h"
#include "shared.h"

namespace patchcull::gl {

using namespace detail;

const char* query_method_name(QueryMethod method) {
    switch (method) {
        case QueryMethod::stop_and_wait:
            return "stop-and-wait";
        case QueryMethod::batched:
            return "batched";
        case QueryMethod::chc:
            return "chc";
        case QueryMethod::chcpp:
            return "chc++";
    }
    return "?";
}

bool parse_query_method(const std::string& text, QueryMethod& method) {
    for (QueryMethod m : {QueryMethod::stop_and_wait, QueryMethod::batched, QueryMethod::chc, QueryMethod::chcpp})
        if (text == query_method_name(m)) {
            method = m;
            return true;
        }
    return false;
}

namespace {

constexpr std::uint32_t kNone = ~std::uint32_t{0};

// The lecture's fit of the visibility persistence: the probability that a node hidden for t
// frames stays hidden in the next.
double persistence(std::uint32_t hidden_frames) { return 0.99 - 0.7 * std::exp(-double(hidden_frames)); }

// A box widened for a query proxy (gl_object_queries.h): kQueryBoxMargin of its diagonal, the
// float rounding of coordinates of its size (the GPU transforms both the proxy and the object in
// float), and the world distance over which window depth changes by 16 ulps of a depth near 1
// at the box's far corner (depth rounding of the proxy and of the surfaces it is compared with).
Bounds widened_query_box(const Bounds& box, const Mat4& world_to_clip, Vec3 eye) {
    const Vec3 d = box.max - box.min;
    const float diag = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    const float extent = std::max({std::fabs(box.min.x), std::fabs(box.min.y), std::fabs(box.min.z),
                                   std::fabs(box.max.x), std::fabs(box.max.y), std::fabs(box.max.z)});
    // The corner farthest from the eye, and the depth slope along the ray to it, in double.
    Vec3 far{eye.x < box.center().x ? box.max.x : box.min.x, eye.y < box.center().y ? box.max.y : box.min.y,
             eye.z < box.center().z ? box.max.z : box.min.z};
    auto window_depth = [&](double t) {
        double c[4] = {0, 0, 0, 0};
        const double p[4] = {eye.x + t * (double(far.x) - eye.x), eye.y + t * (double(far.y) - eye.y),
                             eye.z + t * (double(far.z) - eye.z), 1.0};
        for (int r = 0; r < 4; ++r)
            for (int k = 0; k < 4; ++k) c[r] += double(world_to_clip.at(r, k)) * p[k];
        return c[3] != 0 ? c[2] / c[3] : 0.0;
    };
    const Vec3 to_far = far - eye;
    const double distance =
        std::sqrt(double(to_far.x) * to_far.x + double(to_far.y) * to_far.y + double(to_far.z) * to_far.z);
    double depth_margin = 0;
    if (distance > 0) {
        const double slope = (window_depth(1.0) - window_depth(1.0 - 1e-3)) / (distance * 1e-3);
        if (slope > 0 && std::isfinite(slope)) depth_margin = 16.0 * 0x1p-24 / slope;
    }
    const float margin = kQueryBoxMargin * diag + 4e-7f * extent + static_cast<float>(std::min(depth_margin, 1e30));
    return {box.min - Vec3{margin, margin, margin}, box.max + Vec3{margin, margin, margin}};
}

// True when every corner of the box is in front of the near plane (zero-to-one clip depth: z >= 0
// and w > 0): its proxy is rasterised whole. Otherwise the near plane clips it and the query
// could miss pixels of what it holds.
bool queryable(const Bounds& box, const Mat4& world_to_clip) {
    for (int c = 0; c < 8; ++c) {
        const Vec3 p{(c & 4) ? box.max.x : box.min.x, (c & 2) ? box.max.y : box.min.y, (c & 1) ? box.max.z : box.min.z};
        const Vec4 clip = world_to_clip * homogeneous(p);
        if (!(clip.w > 0) || !(clip.z > 0)) return false;
    }
    return true;
}

float distance_to_box(Vec3 eye, const Bounds& box) {
    const float dx = std::max({box.min.x - eye.x, 0.0f, eye.x - box.max.x});
    const float dy = std::max({box.min.y - eye.y, 0.0f, eye.y - box.max.y});
    const float dz = std::max({box.min.z - eye.z, 0.0f, eye.z - box.max.z});
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

}  // namespace

struct ObjectQueries::Impl {
    GLuint program = 0, vao = 0, box_buffer = 0;
    GLint world_to_clip_loc = -1;
    std::vector<GLuint> pool[2];  // query objects per target (next_query), reused every frame
    std::size_t pool_used[2] = {0, 0};

    // This frame's input.
    QueryOptions options;
    Mat4 world_to_clip;
    ClipDepth depth = ClipDepth::zero_to_one;
    Vec3 eye;
    std::vector<Bounds> boxes;  // per object
    std::vector<std::uint32_t> patches;
    std::vector<Bounds> tight;
    std::vector<std::uint32_t> tight_first;

    // The tree and its history.
    ObjectBvh bvh;
    std::size_t nodes = 0, objects = 0;  // tree: [0, nodes) BVH nodes, [nodes, nodes + objects) objects
    std::vector<std::uint32_t> parent;
    std::vector<std::uint8_t> visible;
    std::vector<std::int64_t> last_visited;
    std::vector<std::uint32_t> hidden_frames;
    std::vector<std::uint32_t> phase;  // CHC++: an object's query phase in visible_interval
    std::int64_t frame = 0;
    std::mt19937_64 rng{1};

    // Per frame, per tree node.
    std::vector<Bounds> query_box;  // widened
    std::vector<std::uint8_t> can_query, outside;
    std::vector<float> near_distance;
    std::vector<std::uint64_t> weight;  // patches under the node
    std::vector<float> gpu_boxes;       // 8 floats per box: the tree's boxes, then the tight ones
    std::vector<std::uint8_t> drawn;
    QueryStats stats;

    ObjectDrawer* drawer = nullptr;
    bool proxy_mode = false;

    // ---- GL helpers ----
    // A query object takes its target at its first use: one pool per target.
    GLuint next_query() {
        const std::size_t k = query_target() == GL_ANY_SAMPLES_PASSED_CONSERVATIVE ? 0 : 1;
        if (pool_used[k] == pool[k].size()) {
            GLuint q = 0;
            glGenQueries(1, &q);
            pool[k].push_back(q);
        }
        return pool[k][pool_used[k]++];
    }
    void enter_proxy_mode() {
        if (proxy_mode) return;
        drawer->renderer().begin_depth_test_draws();
        glUseProgram(program);
        glBindVertexArray(vao);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shared::kBindingQueryBoxes, box_buffer);
        proxy_mode = true;
    }
    void leave_proxy_mode() {
        if (!proxy_mode) return;
        glBindVertexArray(0);
        glUseProgram(0);
        drawer->renderer().end_depth_test_draws();
        proxy_mode = false;
    }
    GLenum query_target() const {
        return options.pixel_threshold == 0 && options.any_samples ? GL_ANY_SAMPLES_PASSED_CONSERVATIVE
                                                                   : GL_SAMPLES_PASSED;
    }
    // Draws tree node t's proxy: CHC++'s tight boxes for an object when asked, else its box.
    void draw_proxy(std::uint32_t t) {
        if (t >= nodes && options.method == QueryMethod::chcpp && options.tight_bounds && !tight_first.empty()) {
            const std::size_t o = t - nodes;
            const std::uint32_t first = tight_first[o], end = tight_first[o + 1];
            if (end > first) {
                glDrawArrays(GL_TRIANGLES, static_cast<GLint>(36 * (nodes + objects + first)),
                             static_cast<GLsizei>(36 * (end - first)));
                stats.proxy_boxes += end - first;
                return;
            }
        }
        glDrawArrays(GL_TRIANGLES, static_cast<GLint>(36 * t), 36);
        ++stats.proxy_boxes;
    }
    GLuint issue(const std::uint32_t* tree_nodes, std::size_t count) {
        enter_proxy_mode();
        const GLuint q = next_query();
        glBeginQuery(query_target(), q);
        for (std::size_t k = 0; k < count; ++k) draw_proxy(tree_nodes[k]);
        glEndQuery(query_target());
        ++stats.queries;
        if (count > 1) ++stats.multiqueries;
        return q;
    }
    static bool available(GLuint q) {
        GLuint ready = 0;
        glGetQueryObjectuiv(q, GL_QUERY_RESULT_AVAILABLE, &ready);
        return ready != 0;
    }
    bool passed(GLuint q) {
        if (!available(q)) ++stats.waits;
        GLuint samples = 0;
        glGetQueryObjectuiv(q, GL_QUERY_RESULT, &samples);
        return samples > options.pixel_threshold;
    }
    void draw_object(std::size_t o) {
        if (drawn[o]) return;
        leave_proxy_mode();
        drawn[o] = 1;
        drawer->draw(o);
    }

    // ---- the tree ----
    bool is_object(std::uint32_t t) const { return t >= nodes; }
    const Bounds& box_of(std::uint32_t t) const { return t < nodes ? bvh.node_box(t) : boxes[t - nodes]; }
    template <typename Visit>
    void for_children(std::uint32_t t, Visit visit) const {
        if (t >= nodes) return;
        if (bvh.node_is_leaf(t)) {
            for (std::size_t k = 0; k < bvh.node_object_count(t); ++k)
                visit(static_cast<std::uint32_t>(nodes + bvh.node_object(t, k)));
        } else {
            visit(static_cast<std::uint32_t>(bvh.node_left(t)));
            visit(static_cast<std::uint32_t>(bvh.node_left(t) + 1));
        }
    }

    void rebuild() {
        bvh.build(boxes.data(), boxes.size());
        nodes = bvh.node_count();
        objects = boxes.size();
        const std::size_t total = nodes + objects;
        parent.assign(total, kNone);
        for (std::uint32_t t = 0; t < nodes; ++t) for_children(t, [&](std::uint32_t c) { parent[c] = t; });
        visible.assign(total, 0);
        last_visited.assign(total, -2);
        hidden_frames.assign(total, 0);
        phase.resize(objects);
        rng.seed(options.seed);
        for (std::uint32_t& p : phase) p = static_cast<std::uint32_t>(rng() % options.visible_interval);
    }

    // Per-frame node data and the proxy buffer.
    void prepare_frame() {
        const std::size_t total = nodes + objects;
        query_box.resize(total);
        can_query.resize(total);
        outside.resize(total);
        near_distance.resize(total);
        weight.assign(total, 0);
        const FrustumPlanes planes = make_frustum_planes(world_to_clip, depth);
        // The box margins and the near-plane test read depth in the zero-to-one form (the same
        // depth slopes, up to sign, in every convention).
        const Mat4 zero_to_one = to_zero_to_one(world_to_clip, depth);
        for (std::uint32_t t = 0; t < total; ++t) {
            const Bounds& b = box_of(t);
            query_box[t] = widened_query_box(b, zero_to_one, eye);
            can_query[t] = queryable(query_box[t], zero_to_one);
            PlaneCullState state;
            std::uint32_t plane_tests = 0;
            outside[t] = classify_aabb(planes, b, state, plane_tests) == Containment::outside;
            near_distance[t] = distance_to_box(eye, b);
        }
        for (std::size_t o = 0; o < objects; ++o) weight[nodes + o] = patches.empty() ? 1 : patches[o];
        // Children have larger indices than their parents in ObjectBvh: sum from the back.
        for (std::size_t t = total; t-- > 0;)
            if (parent[t] != kNone) weight[parent[t]] += weight[t];
        gpu_boxes.resize(8 * (total + tight.size()));
        auto put = [&](std::size_t k, const Bounds& b) {
            const float v[8] = {b.min.x, b.min.y, b.min.z, 1, b.max.x, b.max.y, b.max.z, 1};
            std::copy(v, v + 8, gpu_boxes.begin() + static_cast<std::ptrdiff_t>(8 * k));
        };
        for (std::size_t t = 0; t < total; ++t) put(t, query_box[t]);
        // A tight box is widened as its object's box is (the same margins, scaled to its size).
        for (std::size_t k = 0; k < tight.size(); ++k) put(total + k, widened_query_box(tight[k], zero_to_one, eye));
        upload(box_buffer, gpu_boxes.size() * sizeof(float), gpu_boxes.data());
        glProgramUniformMatrix4fv(program, world_to_clip_loc, 1, GL_FALSE, world_to_clip.m);
        check_gl("ObjectQueries frame setup");
    }

    // ---- the flat methods ----
    void run_flat() {
        std::vector<std::uint32_t> order;
        for (std::uint32_t o = 0; o < objects; ++o) order.push_back(static_cast<std::uint32_t>(nodes + o));
        if (options.front_to_back)
            std::stable_sort(order.begin(), order.end(),
                             [&](std::uint32_t a, std::uint32_t b) { return near_distance[a] < near_distance[b]; });
        const std::size_t batch = options.method == QueryMethod::stop_and_wait ? 1 : options.batch_size;
        std::vector<std::pair<std::uint32_t, GLuint>> pending;
        for (std::size_t at = 0; at < order.size(); at += batch) {
            pending.clear();
            for (std::size_t k = at; k < std::min(order.size(), at + batch); ++k) {
                const std::uint32_t t = order[k];
                if (outside[t]) continue;
                if (!can_query[t]) {
                    ++stats.unqueryable;
                    draw_object(t - nodes);
                    continue;
                }
                pending.push_back({t, issue(&t, 1)});
            }
            for (const auto& [t, q] : pending)
                if (passed(q)) draw_object(t - nodes);
        }
    }

    // ---- CHC and CHC++ ----
    struct Pending {
        GLuint query;
        std::vector<std::uint32_t> nodes;  // more than one: a multiquery
        bool traverse_on_visible;          // false: a previously visible object's query (CHC)
    };
    struct ByDistance {
        const std::vector<float>* d;
        bool operator()(std::uint32_t a, std::uint32_t b) const { return (*d)[a] > (*d)[b]; }
    };

    void pull_up(std::uint32_t t) {
        while (t != kNone && !visible[t]) {
            visible[t] = 1;
            t = parent[t];
        }
    }

    void run_chc(bool plus) {
        std::priority_queue<std::uint32_t, std::vector<std::uint32_t>, ByDistance> to_visit(ByDistance{&near_distance});
        std::deque<Pending> query_queue;
        std::vector<std::uint32_t> i_queue, v_queue;
        std::vector<std::pair<std::uint32_t, GLuint>> v_issued;
        std::vector<std::uint32_t> visited;
        auto traverse = [&](std::uint32_t t) {
            if (is_object(t))
                draw_object(t - nodes);
            else
                for_children(t, [&](std::uint32_t c) { to_visit.push(c); });
        };
        auto issue_single = [&](std::uint32_t t, bool traverse_on_visible) {
            query_queue.push_back({issue(&t, 1), {t}, traverse_on_visible});
        };
        // CHC++: the I-queue as multiqueries (greedy over the nodes sorted by hidden frames).
        auto flush_i_queue = [&] {
            if (i_queue.empty()) return;
            if (!options.multiqueries) {
                for (std::uint32_t t : i_queue) issue_single(t, true);
                i_queue.clear();
                return;
            }
            std::stable_sort(i_queue.begin(), i_queue.end(),
                             [&](std::uint32_t a, std::uint32_t b) { return hidden_frames[a] > hidden_frames[b]; });
            std::size_t at = 0;
            while (at < i_queue.size()) {
                double all_hidden = 1, patch_sum = 0, best_value = -1;
                std::size_t best = 1;
                for (std::size_t n = 1; at + n <= i_queue.size(); ++n) {
                    const std::uint32_t t = i_queue[at + n - 1];
                    all_hidden *= persistence(hidden_frames[t]);
                    patch_sum += double(weight[t]);
                    const double value = all_hidden * patch_sum / (1.0 + double(options.c1) * double(n));
                    if (value > best_value) {
                        best_value = value;
                        best = n;
                    }
                }
                std::vector<std::uint32_t> group(i_queue.begin() + static_cast<std::ptrdiff_t>(at),
                                                 i_queue.begin() + static_cast<std::ptrdiff_t>(at + best));
                query_queue.push_back({issue(group.data(), group.size()), group, true});
                at += best;
            }
            i_queue.clear();
        };
        auto issue_v_queue = [&] {
            for (std::uint32_t t : v_queue) v_issued.push_back({t, issue(&t, 1)});
            v_queue.clear();
        };
        auto process = [&](Pending& p) {
            if (!passed(p.query)) return;  // hidden: every node stays invisible
            if (p.nodes.size() > 1) {      // a multiquery that passed: ask node by node
                ++stats.multiquery_passed;
                for (std::uint32_t t : p.nodes) issue_single(t, true);
                return;
            }
            const std::uint32_t t = p.nodes[0];
            pull_up(t);
            if (p.traverse_on_visible) traverse(t);
        };

        if (nodes > 0) to_visit.push(0);
        while (!to_visit.empty() || !query_queue.empty() || !i_queue.empty()) {
            while (!query_queue.empty() && (to_visit.empty() || available(query_queue.front().query))) {
                if (plus && !available(query_queue.front().query)) {  // fill the wait
                    flush_i_queue();
                    issue_v_queue();
                }
                Pending p = std::move(query_queue.front());
                query_queue.pop_front();
                process(p);
            }
            if (to_visit.empty()) {
                if (plus) flush_i_queue();  // nothing else to do: issue what waits
                continue;
            }
            const std::uint32_t t = to_visit.top();
            to_visit.pop();
            visited.push_back(t);
            if (outside[t]) {
                visible[t] = 0;
                last_visited[t] = frame;
                continue;
            }
            const bool was_visible = visible[t] && last_visited[t] == frame - 1;
            visible[t] = 0;
            last_visited[t] = frame;
            if (!can_query[t]) {  // the near plane clips its proxy: visible without a query
                ++stats.unqueryable;
                pull_up(t);
                traverse(t);
                continue;
            }
            if (was_visible && !is_object(t)) {  // opened: its children decide
                traverse(t);
                continue;
            }
            if (was_visible) {  // a previously visible object: drawn now, its query for the next frame
                if (plus) {
                    const std::uint32_t interval = options.visible_interval;
                    if ((std::uint64_t(frame) + phase[t - nodes]) % interval == 0)
                        v_queue.push_back(t);
                    else
                        pull_up(t);  // assumed visible this frame (no query)
                } else {
                    issue_single(t, false);
                }
                traverse(t);
                continue;
            }
            if (plus) {
                i_queue.push_back(t);
                if (i_queue.size() >= options.batch_size) flush_i_queue();
            } else {
                issue_single(t, true);
            }
        }
        if (plus) {
            issue_v_queue();
            for (const auto& [t, q] : v_issued)
                if (passed(q)) pull_up(t);
        }
        for (std::uint32_t t : visited) hidden_frames[t] = visible[t] ? 0 : hidden_frames[t] + 1;
    }
};

ObjectQueries::ObjectQueries(const GlContext& ctx) : ObjectQueries((ctx.make_current(), Current{})) {}
ObjectQueries::ObjectQueries() : ObjectQueries(Current{}) {}

ObjectQueries::ObjectQueries(Current) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.program =
        link_program({{"object_queries.vert.glsl", GL_VERTEX_SHADER}, {"object_queries.frag.glsl", GL_FRAGMENT_SHADER}},
                     "object queries");
    m.world_to_clip_loc = glGetUniformLocation(m.program, "u_world_to_clip");
    glCreateVertexArrays(1, &m.vao);
    glCreateBuffers(1, &m.box_buffer);
    check_gl("ObjectQueries setup");
}
ObjectQueries::ObjectQueries(ObjectQueries&&) noexcept = default;
ObjectQueries& ObjectQueries::operator=(ObjectQueries&&) noexcept = default;
ObjectQueries::~ObjectQueries() {
    if (!impl_) return;
    Impl& m = *impl_;
    for (const std::vector<GLuint>& pool : m.pool)
        if (!pool.empty()) glDeleteQueries(static_cast<GLsizei>(pool.size()), pool.data());
    glDeleteBuffers(1, &m.box_buffer);
    glDeleteVertexArrays(1, &m.vao);
    glDeleteProgram(m.program);
}

void ObjectQueries::set_frame(const FrameObjects& frame, const QueryOptions& options) {
    if (options.batch_size == 0) throw Error("ObjectQueries: batch size 0 (it must be at least 1)");
    if (options.visible_interval == 0) throw Error("ObjectQueries: visible interval 0 (it must be at least 1)");
    if (frame.count > 0 && !frame.boxes)
        throw Error("ObjectQueries: no boxes for " + std::to_string(frame.count) + " objects");
    Impl& m = *impl_;
    const bool rebuild = frame.count != m.objects || m.parent.empty() || options.seed != m.options.seed ||
                         options.visible_interval != m.options.visible_interval;
    m.options = options;
    m.world_to_clip = frame.world_to_clip;
    m.depth = frame.depth;
    m.eye = frame.eye;
    m.boxes.assign(frame.boxes, frame.boxes + frame.count);
    m.patches.clear();
    if (frame.patches) m.patches.assign(frame.patches, frame.patches + frame.count);
    m.tight.clear();
    m.tight_first.clear();
    if (frame.tight && frame.tight_first) {
        for (std::size_t o = 0; o < frame.count; ++o)
            if (frame.tight_first[o + 1] < frame.tight_first[o])
                throw Error("ObjectQueries: tight_first descends at object " + std::to_string(o));
        m.tight_first.assign(frame.tight_first, frame.tight_first + frame.count + 1);
        m.tight.assign(frame.tight + frame.tight_first[0], frame.tight + frame.tight_first[frame.count]);
        for (std::uint32_t& f : m.tight_first) f -= frame.tight_first[0];
    }
    if (rebuild)
        m.rebuild();
    else
        m.bvh.refit(m.boxes.data());
}

void ObjectQueries::run(ObjectDrawer& drawer) {
    Impl& m = *impl_;
    m.drawer = &drawer;
    m.stats = {};
    m.stats.objects = static_cast<std::uint32_t>(m.objects);
    m.pool_used[0] = m.pool_used[1] = 0;
    m.drawn.assign(m.objects, 0);
    ++m.frame;
    m.prepare_frame();
    if (m.options.method == QueryMethod::stop_and_wait || m.options.method == QueryMethod::batched)
        m.run_flat();
    else
        m.run_chc(m.options.method == QueryMethod::chcpp);
    m.leave_proxy_mode();
    check_gl("ObjectQueries run");
    for (std::size_t o = 0; o < m.objects; ++o) {
        if (m.drawn[o])
            ++m.stats.drawn;
        else if (m.outside[m.nodes + o])
            ++m.stats.frustum_culled;
        else
            ++m.stats.occlusion_culled;
    }
    m.drawer = nullptr;
}

void ObjectQueries::reset() {
    Impl& m = *impl_;
    std::fill(m.visible.begin(), m.visible.end(), 0);
    std::fill(m.last_visited.begin(), m.last_visited.end(), -2);
    std::fill(m.hidden_frames.begin(), m.hidden_frames.end(), 0);
}

const QueryStats& ObjectQueries::stats() const { return impl_->stats; }
const std::vector<std::uint8_t>& ObjectQueries::drawn() const { return impl_->drawn; }

}  // namespace patchcull::gl

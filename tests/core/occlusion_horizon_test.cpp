// Occlusion horizon (patchcull/objects/occlusion_horizon.h): on random city scenes (box buildings on a
// ground, characters in the streets and behind buildings, floating, huge, flat, empty, NaN and
// infinite boxes; eyes 0.2..20 up, pitched, rolled, on building faces; 1x1 .. 200x120 images;
// both depth conventions; coordinates near 0 and 1e4 away) no object reported occluded has a
// pixel centre whose ray hits it at or before the nearest occluder (CPU ray cast in double through
// the same float matrix), every point of the stored horizon is covered by an occluder, and a fair
// share of the truly hidden objects is culled. Then the cases that must come out one way: a
// character behind a tall building in a street canyon is occluded, one in front is not; an
// occluder behind an object never hides it; the horizon of a wall is its projected top edge.
#include "patchcull/objects/occlusion_horizon.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "patchcull/core/clip_space.h"
#include "patchcull/core/error.h"

using namespace patchcull;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInfF = std::numeric_limits<float>::infinity();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

struct Camera {
    Mat4 world_to_clip;
    ClipDepth depth = ClipDepth::zero_to_one;
    int width = 64, height = 48;
};

// yaw about +y (0: looking down -z), pitch up from the horizontal, roll about the view direction.
Camera make_camera(Vec3 eye, double yaw, double pitch, double roll, double fovy, int width, int height, float z_near,
                   float z_far, ClipDepth depth) {
    const Vec3 forward{float(std::cos(pitch) * std::sin(yaw)), float(std::sin(pitch)),
                       float(-std::cos(pitch) * std::cos(yaw))};
    const Vec3 side = normalize(cross(forward, Vec3{0, 1, 0}));
    const Vec3 up0 = cross(side, forward);
    const Vec3 up = up0 * float(std::cos(roll)) - side * float(std::sin(roll));
    Camera c;
    c.world_to_clip =
        perspective(float(fovy), float(width) / float(height), z_near, z_far, depth) * look_at(eye, eye + forward, up);
    c.depth = depth;
    c.width = width;
    c.height = height;
    return c;
}

bool has_nan(const Bounds& b) {
    return std::isnan(b.min.x) || std::isnan(b.min.y) || std::isnan(b.min.z) || std::isnan(b.max.x) ||
           std::isnan(b.max.y) || std::isnan(b.max.z);
}
bool is_empty(const Bounds& b) { return b.min.x > b.max.x || b.min.y > b.max.y || b.min.z > b.max.z; }
bool is_finite_box(const Bounds& b) { return is_finite(b.min) && is_finite(b.max); }

// Ground truth: rays through window points from the eye of the (float) matrix, boxes cast in double.
class RayCaster {
public:
    explicit RayCaster(const Camera& cam) : cam_(cam) {
        EXPECT_TRUE(invert_double(cam.world_to_clip, inv_));
        double e[4];
        unproject(0, 0, 1, 0, e);
        for (int i = 0; i < 3; ++i) eye_[i] = e[i] / e[3];
        const Mat4 m = to_zero_to_one(cam.world_to_clip, cam.depth);
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) m_[r][c] = m.at(r, c);
    }

    // The ray through window point (x, y): origin eye(), direction dir.
    void ray(double x, double y, double dir[3]) const {
        double p[4];
        unproject(2 * x / cam_.width - 1, 2 * y / cam_.height - 1, 0.5, 1, p);
        for (int i = 0; i < 3; ++i) dir[i] = p[i] / p[3] - eye_[i];
    }
    const double* eye() const { return eye_; }

    // Entry parameter (>= 0) of the ray into the closed box, or +inf when it misses.
    static double entry(const double o[3], const double d[3], const Bounds& b) {
        const double lo[3] = {b.min.x, b.min.y, b.min.z}, hi[3] = {b.max.x, b.max.y, b.max.z};
        double t0 = 0, t1 = kInf;
        for (int a = 0; a < 3; ++a) {
            if (d[a] == 0) {
                if (o[a] < lo[a] || o[a] > hi[a]) return kInf;
                continue;
            }
            double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
        }
        return t0 <= t1 ? t0 : kInf;
    }

    // Occluders the truth may count: valid boxes wholly in front of the eye and inside the depth
    // range (others are depth-clipped when drawn). No margins: a superset of what cull() uses.
    bool truth_occluder(const Bounds& b) const {
        if (has_nan(b) || is_empty(b) || !is_finite_box(b)) return false;
        for (int k = 0; k < 8; ++k) {
            const double p[3] = {(k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y, (k & 4) ? b.max.z : b.min.z};
            const double z = m_[2][0] * p[0] + m_[2][1] * p[1] + m_[2][2] * p[2] + m_[2][3];
            const double w = m_[3][0] * p[0] + m_[3][1] * p[1] + m_[3][2] * p[2] + m_[3][3];
            if (!(w > 0 && z >= 0 && z <= w)) return false;
        }
        return true;
    }

private:
    void unproject(double x, double y, double z, double w, double out[4]) const {
        const double in[4] = {x, y, z, w};
        for (int r = 0; r < 4; ++r)
            out[r] = inv_[r][0] * in[0] + inv_[r][1] * in[1] + inv_[r][2] * in[2] + inv_[r][3] * in[3];
    }
    Camera cam_;
    double inv_[4][4]{}, m_[4][4]{}, eye_[3]{};
};

// Per pixel centre, its ray and the nearest truth occluder's entry (computed on first use).
class OccluderDepths {
public:
    OccluderDepths(const RayCaster& rc, const Camera& cam, const std::vector<Bounds>& occluders)
        : rc_(rc), width_(cam.width), t_(std::size_t(cam.width) * cam.height, -1), dir_(3 * t_.size()) {
        for (const Bounds& b : occluders)
            if (rc.truth_occluder(b)) occluders_.push_back(b);
        for (int py = 0; py < cam.height; ++py)
            for (int px = 0; px < cam.width; ++px)
                rc.ray(px + 0.5, py + 0.5, &dir_[3 * (std::size_t(py) * width_ + px)]);
    }
    const double* dir(int px, int py) const { return &dir_[3 * (std::size_t(py) * width_ + px)]; }
    double at(int px, int py) {
        double& t = t_[std::size_t(py) * width_ + px];
        if (t < 0) {
            t = kInf;
            for (const Bounds& b : occluders_) t = std::min(t, RayCaster::entry(rc_.eye(), dir(px, py), b));
        }
        return t;
    }
    const std::vector<Bounds>& occluders() const { return occluders_; }

private:
    const RayCaster& rc_;
    int width_;
    std::vector<double> t_, dir_;
    std::vector<Bounds> occluders_;
};

enum class Truth { outside_view, hidden, visible };

// Whether the object's box is hit at some pixel centre at or before the nearest occluder.
Truth truth_of(const RayCaster& rc, OccluderDepths& depths, const Camera& cam, const Bounds& object,
               int* where = nullptr) {
    bool hit = false;
    for (int py = 0; py < cam.height; ++py)
        for (int px = 0; px < cam.width; ++px) {
            const double t = RayCaster::entry(rc.eye(), depths.dir(px, py), object);
            if (t == kInf) continue;
            hit = true;
            if (t <= depths.at(px, py)) {
                if (where) where[0] = px, where[1] = py;
                return Truth::visible;
            }
        }
    return hit ? Truth::hidden : Truth::outside_view;
}

Bounds box(Vec3 lo, Vec3 hi) { return {lo, hi}; }
Bounds shifted(Bounds b, Vec3 offset) { return {b.min + offset, b.max + offset}; }

struct CityScene {
    Camera cam;
    std::vector<Bounds> occluders, objects;
};

CityScene random_city(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    auto uni = [&](double a, double b) { return float(a + (b - a) * u(rng)); };
    CityScene s;
    const int blocks_x = 2 + int(u(rng) * 5), blocks_z = 2 + int(u(rng) * 5);
    const float block = uni(8, 25), street = uni(3, 10), spacing = block + street;
    const float x_origin = -0.5f * blocks_x * spacing, z_origin = -0.5f * blocks_z * spacing;
    for (int i = 0; i < blocks_x; ++i)
        for (int j = 0; j < blocks_z; ++j) {
            const float bx = x_origin + i * spacing, bz = z_origin + j * spacing;
            const int buildings = int(u(rng) * 4);  // 0: a plaza
            for (int k = 0; k < buildings; ++k) {
                const float x0 = bx + uni(0, 0.6 * block), z0 = bz + uni(0, 0.6 * block);
                const float x1 = std::min(bx + block, x0 + uni(2, block)),
                            z1 = std::min(bz + block, z0 + uni(2, block));
                s.occluders.push_back(box({x0, 0, z0}, {x1, uni(1, 40), z1}));
            }
        }
    if (u(rng) < 0.5) s.occluders.push_back(box({-1000, -1, -1000}, {1000, 0, 1000}));  // the ground
    if (u(rng) < 0.2) s.occluders.push_back(box({kNaN, 0, 0}, {1, 1, 1}));
    if (u(rng) < 0.2) s.occluders.push_back(box({1, 1, 1}, {0, 2, 2}));  // empty
    if (u(rng) < 0.2) s.occluders.push_back(box({-kInfF, 0, 0}, {1, 1, 1}));
    if (u(rng) < 0.3) {  // flat (a billboard), floating
        const float x = uni(x_origin, -x_origin), z = uni(z_origin, -z_origin), y = uni(0, 20);
        s.occluders.push_back(u(rng) < 0.5 ? box({x, y, z}, {x + uni(1, 20), y + uni(1, 10), z})
                                           : box({x, y, z}, {x, y + uni(1, 10), z + uni(1, 20)}));
    }

    auto street_point = [&]() {
        // On a street line between blocks (x or z), anywhere along it.
        if (u(rng) < 0.5)
            return Vec3{x_origin + int(u(rng) * blocks_x) * spacing - uni(0, street), 0, uni(z_origin, -z_origin)};
        return Vec3{uni(x_origin, -x_origin), 0, z_origin + int(u(rng) * blocks_z) * spacing - uni(0, street)};
    };
    const int objects = 15 + int(u(rng) * 25);
    for (int k = 0; k < objects; ++k) {
        const double kind = u(rng);
        if (kind < 0.35) {  // a character in a street
            const Vec3 p = street_point();
            const float r = uni(0.2, 0.6);
            s.objects.push_back(box({p.x - r, 0, p.z - r}, {p.x + r, uni(1, 2), p.z + r}));
        } else if (kind < 0.6) {  // anywhere in the city, on the ground (behind or inside buildings)
            const float x = uni(x_origin, -x_origin), z = uni(z_origin, -z_origin), r = uni(0.1, 3);
            s.objects.push_back(box({x - r, 0, z - r}, {x + r, uni(0.5, 8), z + r}));
        } else if (kind < 0.72) {  // floating
            const float x = uni(x_origin, -x_origin), z = uni(z_origin, -z_origin), y = uni(3, 60), r = uni(0.1, 4);
            s.objects.push_back(box({x - r, y, z - r}, {x + r, y + uni(0.1, 5), z + r}));
        } else if (kind < 0.77) {  // flat
            const float x = uni(x_origin, -x_origin), z = uni(z_origin, -z_origin), r = uni(0.1, 4);
            s.objects.push_back(u(rng) < 0.5 ? box({x - r, 0, z}, {x + r, uni(0.5, 4), z})
                                             : box({x - r, 1, z - r}, {x + r, 1, z + r}));
        } else if (kind < 0.8) {  // huge
            const float r = uni(50, 5000);
            s.objects.push_back(box({-r, uni(-10, 5), -r}, {r, uni(5, 100), r}));
        } else if (kind < 0.82) {  // tiny
            const Vec3 p = street_point();
            s.objects.push_back(box({p.x, 0.5f, p.z}, {p.x + 0.01f, 0.51f, p.z + 0.01f}));
        } else if (kind < 0.84) {
            s.objects.push_back(box({1, 1, 1}, {0, 2, 2}));  // empty
        } else if (kind < 0.86) {
            s.objects.push_back(box({0, kNaN, 0}, {1, 1, 1}));
        } else if (kind < 0.87) {
            s.objects.push_back(box({0, 0, 0}, {kInfF, 1, 1}));
        } else if (kind < 0.93 && !s.occluders.empty()) {  // an occluder itself, or sharing its face
            Bounds b = s.occluders[std::size_t(u(rng) * s.occluders.size())];
            if (u(rng) < 0.5) b = box({b.max.x, b.min.y, b.min.z}, {b.max.x + 1, b.max.y, b.max.z});
            s.objects.push_back(b);
        } else {  // just behind a building's back face (in some direction)
            const Vec3 p = street_point();
            s.objects.push_back(box({p.x - 0.3f, 0, p.z - 0.3f}, {p.x + 0.3f, 1.8f, p.z + 0.3f}));
        }
    }

    // The eye: in a street (sometimes anywhere, or on a building's face), 0.2..20 up.
    Vec3 eye = street_point();
    if (u(rng) < 0.15) eye = Vec3{uni(x_origin, -x_origin), 0, uni(z_origin, -z_origin)};
    eye.y = uni(0.2, 20);
    if (u(rng) < 0.1 && !s.occluders.empty()) {
        const Bounds& b = s.occluders[std::size_t(u(rng) * s.occluders.size())];
        if (is_finite_box(b) && !is_empty(b)) eye.x = b.min.x;
    }
    const double yaw = 2 * kPi * u(rng), pitch = (-60 + 90 * u(rng)) * kPi / 180;
    const double roll = u(rng) < 0.4 ? (-25 + 50 * u(rng)) * kPi / 180 : 0;
    int width = 64 + int(u(rng) * 137), height = 48 + int(u(rng) * 73);
    if (u(rng) < 0.08) width = 1 + int(u(rng) * 4), height = 1 + int(u(rng) * 4);
    const ClipDepth depth = u(rng) < 0.5 ? ClipDepth::zero_to_one : ClipDepth::minus_one_to_one;

    // Far from the origin in a quarter of the scenes.
    Vec3 offset{};
    if (u(rng) < 0.25)
        offset = Vec3{u(rng) < 0.5 ? 1e4f : -1e4f, u(rng) < 0.5 ? 0.f : 1e4f, u(rng) < 0.5 ? 1e4f : -1e4f};
    for (Bounds& b : s.occluders) b = shifted(b, offset);
    for (Bounds& b : s.objects) b = shifted(b, offset);
    s.cam = make_camera(eye + offset, yaw, pitch, roll, uni(40, 90) * kPi / 180, width, height, uni(0.05, 1),
                        uni(200, 2000), depth);
    return s;
}

std::vector<std::uint8_t> run(OcclusionHorizon& h, const Camera& cam, const std::vector<Bounds>& occluders,
                              const std::vector<Bounds>& objects, HorizonStats* stats_out = nullptr) {
    std::vector<std::uint8_t> occluded(objects.size(), 7);
    HorizonStats stats;
    h.cull(cam.world_to_clip, cam.depth, cam.width, cam.height, occluders.data(), occluders.size(), objects.data(),
           objects.size(), occluded.data(), stats);
    if (stats_out) *stats_out = stats;
    return occluded;
}

}  // namespace

// (1) The property: nothing reported occluded shows a pixel centre, on several hundred scenes.
TEST(OcclusionHorizon, RandomCitiesMatchRayCastTruth) {
    std::mt19937 rng(1234);
    OcclusionHorizon horizon;  // reused across scenes of every size, as a renderer would
    std::size_t hidden_in_view = 0, culled_hidden = 0, culled_total = 0, false_culls = 0, horizon_points = 0;
    for (int scene = 0; scene < 300; ++scene) {
        const CityScene s = random_city(rng);
        HorizonStats stats;
        const auto occluded = run(horizon, s.cam, s.occluders, s.objects, &stats);
        EXPECT_EQ(stats.objects_tested, s.objects.size());
        EXPECT_LE(stats.occluders_inserted + stats.occluders_skipped, s.occluders.size());
        const RayCaster rc(s.cam);
        OccluderDepths depths(rc, s.cam, s.occluders);
        std::size_t occluded_count = 0;
        for (std::size_t i = 0; i < s.objects.size(); ++i) {
            const Bounds& b = s.objects[i];
            ASSERT_TRUE(occluded[i] == 0 || occluded[i] == 1);
            occluded_count += occluded[i];
            if (has_nan(b) || (!is_empty(b) && !is_finite_box(b))) {
                EXPECT_EQ(occluded[i], 0) << "scene " << scene << " object " << i << ": NaN / infinite box";
                continue;
            }
            if (is_empty(b)) {
                EXPECT_EQ(occluded[i], 1) << "scene " << scene << " object " << i << ": empty box";
                continue;
            }
            int where[2] = {-1, -1};
            const Truth truth = truth_of(rc, depths, s.cam, b, where);
            if (occluded[i]) {
                ++culled_total;
                if (truth == Truth::visible) {
                    ++false_culls;
                    ADD_FAILURE() << "scene " << scene << " object " << i << " reported occluded but visible at pixel ("
                                  << where[0] << ", " << where[1] << ")";
                }
            }
            if (truth == Truth::hidden) {
                ++hidden_in_view;
                culled_hidden += occluded[i];
            }
        }
        EXPECT_EQ(stats.objects_occluded, occluded_count);

        // Every stored horizon point is covered by a truth occluder (strip edges and middle).
        const auto& lo = horizon.column_low();
        const auto& hi = horizon.column_high();
        ASSERT_EQ(lo.size(), std::size_t(s.cam.width));
        for (int c = 0; c < s.cam.width; ++c) {
            if (lo[c] > hi[c]) continue;
            EXPECT_GE(lo[c], 0.0f);
            EXPECT_LE(hi[c], float(s.cam.height));
            for (double fx : {0.001, 0.5, 0.999})
                for (int k = 0; k <= 4; ++k) {
                    const double y = lo[c] + (double(hi[c]) - lo[c]) * k / 4;
                    double dir[3];
                    rc.ray(c + fx, y, dir);
                    bool hit = false;
                    for (const Bounds& o : depths.occluders()) hit = hit || RayCaster::entry(rc.eye(), dir, o) < kInf;
                    ++horizon_points;
                    if (!hit)
                        ADD_FAILURE() << "scene " << scene << ": horizon point (" << c + fx << ", " << y
                                      << ") uncovered";
                }
        }

        // Reuse leaves nothing behind: a fresh instance answers the same.
        if (scene % 10 == 0) {
            OcclusionHorizon fresh;
            EXPECT_EQ(run(fresh, s.cam, s.occluders, s.objects), occluded) << "scene " << scene;
        }
    }
    EXPECT_EQ(false_culls, 0u);
    // It must cull: a fair share of the objects in view but hidden (measured: 319 of 487).
    EXPECT_GT(horizon_points, 1000u);
    EXPECT_GT(hidden_in_view, 300u);
    EXPECT_GT(double(culled_hidden), 0.5 * double(hidden_in_view))
        << culled_hidden << " of " << hidden_in_view << " hidden objects culled";
    RecordProperty("hidden_in_view", int(hidden_in_view));
    RecordProperty("culled_hidden", int(culled_hidden));
    std::printf("occlusion horizon: culled %zu of %zu objects hidden in view (%zu culled in all), %zu horizon points\n",
                culled_hidden, hidden_in_view, culled_total, horizon_points);
}

// (2) A street canyon: behind the tall building is occluded, in front of it or above it is not.
TEST(OcclusionHorizon, StreetCanyonCullsBehindTallBuilding) {
    for (const Vec3 offset : {Vec3{0, 0, 0}, Vec3{1e4f, 0, -1e4f}})
        for (const ClipDepth depth : {ClipDepth::zero_to_one, ClipDepth::minus_one_to_one}) {
            const Camera cam =
                make_camera(Vec3{0, 1.7f, 0} + offset, 0, 0, 0, 60 * kPi / 180, 160, 100, 0.1f, 500, depth);
            // Rows of houses along both sides (each 19 deep, 1 apart) and a building across the
            // street 40..60 ahead, 12 high.
            std::vector<Bounds> occluders;
            for (int k = 0; k < 10; ++k) {
                const float z0 = -20.0f * k - 20, z1 = -20.0f * k - 1;
                occluders.push_back(box({-20, 0, z0}, {-4, 15, z1}));
                occluders.push_back(box({4, 0, z0}, {20, 15, z1}));
            }
            occluders.push_back(box({-20, 0, -60}, {20, 12, -40}));
            const std::vector<Bounds> objects0 = {
                box({-1, 0, -80.3f}, {1, 1.8f, -79.7f}),        // 0: behind the building across
                box({-0.3f, 0, -30.3f}, {0.3f, 1.8f, -29.7f}),  // 1: in front of it
                box({-1, 40, -101}, {1, 42, -100}),             // 2: high above it, far behind
                box({30, 0, -100}, {31, 1.8f, -99}),            // 3: in a side street, behind the right row
                box({-2, 0, -61}, {2, 3, -60.5f}),              // 4: just behind the building across
            };
            std::vector<Bounds> objects;
            objects.reserve(objects0.size());
            for (Bounds& b : occluders) b = shifted(b, offset);
            for (const Bounds& b : objects0) objects.push_back(shifted(b, offset));
            OcclusionHorizon horizon;
            HorizonStats stats;
            const auto occluded = run(horizon, cam, occluders, objects, &stats);
            EXPECT_EQ(occluded, (std::vector<std::uint8_t>{1, 0, 0, 1, 1}));
            EXPECT_GT(stats.occluders_inserted, 0u);
            EXPECT_EQ(stats.objects_occluded, 3u);
            // The truth agrees (so the expectations above are the right ones).
            const RayCaster rc(cam);
            OccluderDepths depths(rc, cam, occluders);
            EXPECT_EQ(truth_of(rc, depths, cam, objects[0]), Truth::hidden);
            EXPECT_EQ(truth_of(rc, depths, cam, objects[1]), Truth::visible);
            EXPECT_EQ(truth_of(rc, depths, cam, objects[2]), Truth::visible);
            EXPECT_EQ(truth_of(rc, depths, cam, objects[3]), Truth::hidden);
            EXPECT_EQ(truth_of(rc, depths, cam, objects[4]), Truth::hidden);
        }
}

// (3) Sweep order: an occluder farther than (or overlapping in depth with) the object never
// hides it, however well its projection covers the object's rectangle; in front, it does.
TEST(OcclusionHorizon, FartherOccluderNeverHides) {
    const Camera cam = make_camera({0, 1.7f, 0}, 0, 0, 0, 60 * kPi / 180, 120, 80, 0.1f, 500, ClipDepth::zero_to_one);
    const Bounds object = box({-0.3f, 0, -30.3f}, {0.3f, 1.8f, -29.7f});
    const Bounds behind = box({-200, -50, -50}, {200, 100, -45});
    const Bounds across = box({-200, -50, -35}, {200, 100, -30});       // overlaps the object's depths
    const Bounds touching = box({-200, -50, -29.7f}, {200, 100, -20});  // ends at the object's near face
    const Bounds in_front = box({-200, -50, -20}, {200, 100, -15});
    OcclusionHorizon horizon;
    EXPECT_EQ(run(horizon, cam, {behind}, {object})[0], 0);
    EXPECT_EQ(run(horizon, cam, {across}, {object})[0], 0);
    EXPECT_EQ(run(horizon, cam, {touching}, {object})[0], 0);
    EXPECT_EQ(run(horizon, cam, {object}, {object})[0], 0);  // never hidden by itself
    EXPECT_EQ(run(horizon, cam, {behind, across, object}, {object})[0], 0);
    EXPECT_EQ(run(horizon, cam, {behind, in_front}, {object})[0], 1);
    // Objects are sorted by their nearest depth: the one behind the far wall is hidden by it,
    // the one in front of it is not, whatever their order in the array.
    const Bounds far_object = box({-0.3f, 0, -60.3f}, {0.3f, 1.8f, -59.7f});
    EXPECT_EQ(run(horizon, cam, {behind}, {far_object, object}), (std::vector<std::uint8_t>{1, 0}));
    EXPECT_EQ(run(horizon, cam, {behind}, {object, far_object}), (std::vector<std::uint8_t>{0, 1}));
}

// For an upright camera in front of a wall reaching below the image, each column's horizon is the
// projected top edge (the paper's "maximum of projected heights"), eroded by the pixel margin.
TEST(OcclusionHorizon, WallHorizonIsItsProjectedTop) {
    const int width = 160, height = 100;
    const Camera cam =
        make_camera({0, 1.7f, 0}, 0, 0, 0, 60 * kPi / 180, width, height, 0.1f, 500, ClipDepth::zero_to_one);
    const Bounds wall = box({-1000, -100, -20}, {1000, 10, -19});
    OcclusionHorizon horizon;
    HorizonStats stats;
    const auto occluded = run(horizon, cam, {wall}, {box({-1, 0, -100}, {1, 1, -99})}, &stats);
    EXPECT_EQ(occluded[0], 1);
    EXPECT_EQ(stats.occluders_inserted, 1u);
    // Top front edge (y = 10, z = -19): the highest point of the projection at every x.
    const Vec4 top = cam.world_to_clip * Vec4{0, 10, -19, 1};
    const double expected = (double(top.y) / top.w + 1) * height / 2 - kHorizonPixelMargin;
    for (int c = 0; c < width; ++c) {
        EXPECT_EQ(horizon.column_low()[c], 0.0f) << c;
        EXPECT_NEAR(horizon.column_high()[c], expected, 1e-4) << c;
    }
    // An object far behind reaching just below that edge is occluded, one just above it is not.
    const double top_at_100 = 1.7 + (10 - 1.7) * 100.0 / 19;  // the wall's top edge seen at z = -100
    EXPECT_EQ(run(horizon, cam, {wall}, {box({-1, 0, -101}, {1, float(top_at_100) - 0.5f, -100})})[0], 1);
    EXPECT_EQ(run(horizon, cam, {wall}, {box({-1, 0, -101}, {1, float(top_at_100) + 0.5f, -100})})[0], 0);
}

// Boxes and cameras at the edges of the contract.
TEST(OcclusionHorizon, DegenerateInputs) {
    const Camera cam = make_camera({0, 1.7f, 0}, 0, 0, 0, 60 * kPi / 180, 64, 48, 0.1f, 500, ClipDepth::zero_to_one);
    const Bounds wall = box({-200, -50, -20}, {200, 100, -15});
    const Bounds behind = box({-0.3f, 0, -30.3f}, {0.3f, 1.8f, -29.7f});
    OcclusionHorizon horizon;
    HorizonStats stats;
    // Empty: occluded (draws nothing); NaN and infinite: never; around the eye or behind it: not.
    const std::vector<Bounds> objects = {
        box({1, 1, 1}, {0, 2, 2}),
        box({kNaN, 0, -40}, {1, 1, -39}),
        box({-1, 0, -40}, {1, kInfF, -39}),
        box({-1, 0, -1}, {1, 3, 1}),          // the eye inside
        box({-1, 0, 30}, {1, 3, 31}),         // behind the eye
        box({-300, 0, -40}, {-290, 1, -39}),  // outside the viewport (left), behind the wall
        behind,
    };
    auto occluded = run(horizon, cam, {wall}, objects, &stats);
    EXPECT_EQ(occluded, (std::vector<std::uint8_t>{1, 0, 0, 0, 0, 0, 1}));
    EXPECT_EQ(stats.objects_tested, 7u);
    EXPECT_EQ(stats.objects_occluded, 2u);
    // Occluders that cannot be used are skipped: NaN, empty, infinite, around the eye, behind it,
    // crossing the near or the far plane.
    const std::vector<Bounds> bad = {
        box({kNaN, -50, -20}, {200, 100, -15}),     box({200, -50, -20}, {-200, 100, -15}),
        box({-kInfF, -50, -20}, {200, 100, -15}),   box({-200, -50, -20}, {200, 100, 1}),
        box({-200, -50, 15}, {200, 100, 20}),       box({-200, -50, -20}, {200, 100, -0.05f}),
        box({-2000, -500, -600}, {2000, 1000, -20})};
    stats = {};
    occluded = run(horizon, cam, bad, {behind}, &stats);
    EXPECT_EQ(occluded[0], 0);
    EXPECT_EQ(stats.occluders_skipped, 7u);
    EXPECT_EQ(stats.occluders_inserted, 0u);
    // Tiny images work; bad viewports and null arrays throw.
    for (const auto& [w, h] : {std::pair{1, 1}, std::pair{2, 1}, std::pair{1, 3}}) {
        Camera tiny = cam;
        tiny.width = w, tiny.height = h;
        EXPECT_EQ(run(horizon, tiny, {wall}, {behind})[0], 1) << w << "x" << h;
    }
    std::uint8_t out = 0;
    EXPECT_THROW(horizon.cull(cam.world_to_clip, cam.depth, 0, 48, &wall, 1, &behind, 1, &out, stats), Error);
    EXPECT_THROW(horizon.cull(cam.world_to_clip, cam.depth, 64, 16385, &wall, 1, &behind, 1, &out, stats), Error);
    EXPECT_THROW(horizon.cull(cam.world_to_clip, cam.depth, 64, 48, nullptr, 1, &behind, 1, &out, stats), Error);
    EXPECT_THROW(horizon.cull(cam.world_to_clip, cam.depth, 64, 48, &wall, 1, &behind, 1, nullptr, stats), Error);
    EXPECT_NO_THROW(horizon.cull(cam.world_to_clip, cam.depth, 64, 48, nullptr, 0, nullptr, 0, nullptr, stats));
    // A NaN matrix culls nothing.
    Camera broken = cam;
    broken.world_to_clip.m[5] = kNaN;
    EXPECT_EQ(run(horizon, broken, {wall}, {behind})[0], 0);
}

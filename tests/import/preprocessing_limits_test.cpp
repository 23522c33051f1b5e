// Preprocessing cost on large faces and high valence (patchcull/import/subdivision.h, kMaxFaceCorners,
// kMaxValence): beyond the limits both schemes refuse the mesh at once with one line naming the
// face or vertex (1-based, as in the OBJ); at the limits they build in bounded time. Before the
// limits, a 10000-sided face ran out of memory with acc (std::bad_alloc) and did not finish
// within minutes with osd; a valence-10000 vertex likewise.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>

#include "patchcull/core/error.h"
#include "patchcull/import/subdivision.h"

using namespace patchcull;

namespace {

// One n-gon on the unit circle; closed: a second n-gon with the opposite winding on the same
// corners (every edge then has two faces, and the edge points depend on both face points).
ControlMesh ngon(std::uint32_t n, bool closed) {
    ControlMesh m;
    m.name = "ngon.obj";
    for (std::uint32_t k = 0; k < n; ++k) {
        const float a = 6.2831853f * static_cast<float>(k) / static_cast<float>(n);
        m.positions.push_back({std::cos(a), std::sin(a), 0});
    }
    for (std::uint32_t k = 0; k < n; ++k) m.face_vertices.push_back(k);
    m.face_offsets.push_back(n);
    if (closed) {
        for (std::uint32_t k = 0; k < n; ++k) m.face_vertices.push_back(n - 1 - k);
        m.face_offsets.push_back(2 * n);
    }
    return m;
}

// Vertex 0 of valence n: n quads (0, ring k, outer k, ring k+1); closed: a second fan under it,
// so every edge has two faces and vertex 0's antipode has valence n too.
ControlMesh quad_fan(std::uint32_t n, bool closed) {
    ControlMesh m;
    m.name = "fan.obj";
    m.positions.push_back({0, 0, 0.3f});
    for (int ring = 0; ring < 2; ++ring)
        for (std::uint32_t k = 0; k < n; ++k) {
            const float a = 6.2831853f * (static_cast<float>(k) + 0.5f * ring) / static_cast<float>(n);
            const float r = ring ? 1.2f : 1.0f;
            m.positions.push_back({r * std::cos(a), r * std::sin(a), 0});
        }
    const std::uint32_t bottom = static_cast<std::uint32_t>(m.positions.size());
    if (closed) m.positions.push_back({0, 0, -0.3f});
    const auto ring_v = [n](std::uint32_t k) { return 1 + k % n; };
    const auto outer_v = [n](std::uint32_t k) { return 1 + n + k % n; };
    const auto face = [&m](std::initializer_list<std::uint32_t> v) {
        m.face_vertices.insert(m.face_vertices.end(), v);
        m.face_offsets.push_back(static_cast<std::uint32_t>(m.face_vertices.size()));
    };
    for (std::uint32_t k = 0; k < n; ++k) {
        face({0, ring_v(k), outer_v(k), ring_v(k + 1)});
        if (closed) face({bottom, ring_v(k + 1), outer_v(k), ring_v(k)});
    }
    return m;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void expect_refused(const ControlMesh& mesh, Scheme scheme, const std::string& culprit) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
        build_model(mesh, scheme);
        ADD_FAILURE() << scheme_name(scheme) << ": " << mesh.name << " was accepted";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(mesh.name + ": " + culprit, 0), 0u) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        EXPECT_LT(what.size(), 200u) << what;
    }
    EXPECT_LT(seconds_since(t0), 1.0) << scheme_name(scheme) << ": refusing must come before the work";
}

}  // namespace

TEST(PreprocessingLimits, ATenThousandSidedFaceIsRefusedAtOnce) {
    for (const Scheme scheme : {Scheme::acc, Scheme::osd}) {
        expect_refused(ngon(10000, false), scheme, "face 1 has 10000 corners");
        expect_refused(ngon(10000, true), scheme, "face 1 has 10000 corners");
        expect_refused(ngon(kMaxFaceCorners + 1, false), scheme, "face 1 has 65 corners");
    }
}

TEST(PreprocessingLimits, AValenceTenThousandVertexIsRefusedAtOnce) {
    for (const Scheme scheme : {Scheme::acc, Scheme::osd}) {
        expect_refused(quad_fan(10000, false), scheme, "vertex 1 has valence 10000");
        expect_refused(quad_fan(10000, true), scheme, "vertex 1 has valence 10000");
        expect_refused(quad_fan(kMaxValence + 1, true), scheme, "vertex 1 has valence 65");
    }
    // The first offender is named with its full valence, 1-based: here the second fan's centre.
    ControlMesh m = quad_fan(kMaxValence, false);
    const ControlMesh second = quad_fan(200, false);
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), second.positions.begin(), second.positions.end());
    for (std::uint32_t v : second.face_vertices) m.face_vertices.push_back(base + v);
    for (std::size_t f = 1; f < second.face_offsets.size(); ++f)
        m.face_offsets.push_back(m.face_offsets.back() + second.face_size(f - 1));
    expect_refused(m, Scheme::osd, "vertex " + std::to_string(base + 1) + " has valence 200");
}

TEST(PreprocessingLimits, FacesAndValencesAtTheLimitBuildInBoundedTime) {
    // Measured 0.04-0.3 s each in Release (subdivision.h); the bound leaves room for a loaded machine.
    const ControlMesh meshes[] = {ngon(kMaxFaceCorners, false), ngon(kMaxFaceCorners, true),
                                  quad_fan(kMaxValence, false), quad_fan(kMaxValence, true)};
    for (const ControlMesh& mesh : meshes)
        for (const Scheme scheme : {Scheme::acc, Scheme::osd}) {
            const auto t0 = std::chrono::steady_clock::now();
            const SubdivisionModel model = build_model(mesh, scheme);
            const double s = seconds_since(t0);
            EXPECT_GT(model.patch_count(), 0u);
            EXPECT_EQ(model.patch_points.rows(), 16 * model.patch_count());
            EXPECT_LT(s, 5.0) << scheme_name(scheme) << " " << mesh.name << " faces " << mesh.face_count();
        }
}

// Meshes of several shells, loaded from OBJ files with both schemes (load_model): every shell
// ends up facing out of the solid, a cavity's wall facing into the cavity (nesting parity,
// patchcull/core/mesh.h), checked on the limit surface's normals. The whole-mesh rule (the sign of
// the total signed volume) failed each of these: it called the reversed pairs flat (two-sided),
// kept a cavity facing the material, and reversed the innermost of three nested spheres.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "patchcull/core/patch.h"
#include "patchcull/import/model_loader.h"

using namespace patchcull;

namespace {

std::string shells_file(const char* name) { return std::string(PATCHCULL_SOURCE_DIR) + "/tests/data/shells/" + name; }

// A shell of a file written by tests/data/shells/make_shells.py: its faces, its centre, and
// where its normals must point: +1 away from the centre (bounds the solid from outside), -1
// towards it (a cavity's wall). major > 0: a torus around the z axis (away from its core circle).
struct ShellSpec {
    std::uint32_t first_face, faces;
    Vec3 centre;
    int sign;
    float major = 0;
};

void expect_shells_face_out(const char* file, const std::vector<ShellSpec>& shells, const char* warning) {
    for (const Scheme scheme : {Scheme::acc, Scheme::osd}) {
        const std::string name = std::string(file) + (scheme == Scheme::acc ? " acc" : " osd");
        SCOPED_TRACE(name);
        const LoadedModel m = load_model(shells_file(file), scheme, 0);
        EXPECT_TRUE(m.closed);  // one-sided, back-patch culled
        if (*warning) {
            ASSERT_EQ(m.warnings.size(), 1u);
            EXPECT_NE(m.warnings[0].find(warning), std::string::npos) << m.warnings[0];
        } else {
            EXPECT_TRUE(m.warnings.empty()) << m.warnings[0];
        }
        ASSERT_FALSE(m.rest.patches.empty());
        std::vector<std::size_t> checked(shells.size(), 0);
        for (std::size_t p = 0; p < m.rest.patches.size(); ++p) {
            const std::uint32_t face = m.rest.info[p].base_face;
            for (std::size_t s = 0; s < shells.size(); ++s) {
                const ShellSpec& spec = shells[s];
                if (face < spec.first_face || face >= spec.first_face + spec.faces) continue;
                for (const float u : {0.25f, 0.5f, 0.75f}) {
                    const SurfacePoint sp = evaluate_surface(m.rest.patches[p], u, 1 - u);
                    Vec3 away = sp.position - spec.centre;
                    if (spec.major > 0) {  // from the nearest point of the core circle
                        const float r = std::sqrt(away.x * away.x + away.y * away.y);
                        away = away - Vec3{away.x / r * spec.major, away.y / r * spec.major, 0};
                    }
                    EXPECT_GT(dot(normalize(sp.normal), normalize(away)) * float(spec.sign), 0.0f)
                        << "patch " << p << " of face " << face << " (shell " << s << ")";
                }
                ++checked[s];
            }
        }
        for (std::size_t s = 0; s < shells.size(); ++s) EXPECT_GT(checked[s], 0u) << "shell " << s;
    }
}

// Each sphere of make_shells.py has 54 faces, each torus 32.
constexpr std::uint32_t kSphere = 54, kTorus = 32;

}  // namespace

TEST(ShellOrientation, TwoSpheresOneReversedBothFaceOut) {
    expect_shells_face_out("two_spheres.obj", {{0, kSphere, {-1.5f, 0, 0}, +1}, {kSphere, kSphere, {1.5f, 0, 0}, +1}},
                           "");
    expect_shells_face_out("two_spheres_one_reversed.obj",
                           {{0, kSphere, {-1.5f, 0, 0}, +1}, {kSphere, kSphere, {1.5f, 0, 0}, +1}},
                           "1 of 2 closed shells oriented inward");
}

TEST(ShellOrientation, HollowSolidsCavityFacesIntoIt) {
    expect_shells_face_out("hollow_sphere.obj", {{0, kSphere, {0, 0, 0}, +1}, {kSphere, kSphere, {0.2f, 0.1f, 0}, -1}},
                           "1 of 2 closed shells oriented inward");
}

TEST(ShellOrientation, NestedSpheresAlternate) {
    // The outer written inside out, the middle (a cavity) and the inner (an island) outward.
    expect_shells_face_out(
        "nested_spheres.obj",
        {{0, kSphere, {0, 0, 0}, +1}, {kSphere, kSphere, {0, 0, 0.1f}, -1}, {2 * kSphere, kSphere, {0.1f, 0, 0}, +1}},
        "2 of 3 closed shells oriented inward");
}

TEST(ShellOrientation, TwoToriOneReversedBothFaceOut) {
    expect_shells_face_out("two_tori_one_reversed.obj",
                           {{0, kTorus, {-2.5f, 0, 0}, +1, 1.5f}, {kTorus, kTorus, {2.5f, 0, 0}, +1, 1.5f}},
                           "1 of 2 closed shells oriented inward");
}

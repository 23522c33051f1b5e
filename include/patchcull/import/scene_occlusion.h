// patchcull/import/scene_occlusion.h: the CPU object-level occlusion methods set up for a
// Scene (scene_model.h), after the object level of scene_object_level.h:
//   horizon  the occlusion horizon (occlusion_horizon.h; Downs, Möller & Séquin, "Occlusion
//            Horizons for Driving through Urban Scenery"): the occluders are the environment
//            objects that are closed boxes (a city's buildings, box_environment_objects), the
//            objects every instance and environment object, tested front to back;
//   portals  cells and portals (portal_culling.h; Luebke & Georges, "Portals and Mirrors"): the
//            scene's cells and portals, an object drawn when its box may be seen through the
//            portal sequence from the eye's cell (every object when the eye is in no cell, or
//            when an environment object reaches between the eye and the near plane: clipped
//            there, or seen from inside, a wall is no wall).
// Both only add culls to what the object level (SceneObjectLevel::cull) left: the result is the
// level's culled spans plus the spans of the objects these methods hide, merged (ascending,
// disjoint), for PipelineParams::object_culled / culled_occluders.
//
// Conservative as their parts: the horizon's occluders are drawn whole every frame they are not
// culled themselves, and an occluder can only hide an object entirely behind it (its far depth
// before the object's near depth), so a culled occluder is itself hidden behind nearer ones that
// are drawn; portals assume the scene author's contract (walls opaque, every opening a portal,
// cells tiling the interior, scene_file.h / SCENE_FORMAT.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "patchcull/core/camera.h"
#include "patchcull/import/scene_model.h"
#include "patchcull/import/scene_object_level.h"
#include "patchcull/objects/object_culling.h"
#include "patchcull/objects/occlusion_horizon.h"
#include "patchcull/objects/portal_culling.h"
#include "patchcull/objects/tight_bounds.h"

namespace patchcull {

/// The environment objects that are closed axis-aligned boxes: non-zero extent on every axis,
/// every vertex of their triangles a corner of their AABB, every triangle in one of its faces, and
/// every face covered by two of them that split it along one diagonal (for one-sided objects, two
/// that face outwards). Drawn, such an object covers every pixel of its box's projection from
/// outside. (Areas alone do not tell: a doubled triangle makes up for a missing one.)
std::vector<std::size_t> box_environment_objects(const Scene& scene);

enum class SceneOcclusionMethod : std::uint8_t { horizon, portals };
/// "horizon", "portals".
const char* scene_occlusion_method_name(SceneOcclusionMethod method);
bool parse_scene_occlusion_method(const std::string& text, SceneOcclusionMethod& method);

/// Counts of one frame.
struct SceneOcclusionStats {
    std::size_t objects_tested = 0;                        ///< objects the object level left
    std::size_t objects_culled = 0;                        ///< of those, hidden by the method
    std::size_t patches_culled = 0, triangles_culled = 0;  ///< in the hidden objects
    HorizonStats horizon;
    PortalStats portals;
    bool eye_in_cell = false;  ///< portals: the eye was in a cell (else nothing is culled)
    /// portals: an environment object's box reached into the pyramid between the eye and the near
    /// plane (clipped walls are no walls): nothing was culled.
    bool near_geometry = false;
};

class SceneOcclusion {
public:
    /// level: the scene's object level (its objects and boxes; it must outlive this object).
    /// Throws patchcull::Error for portals on a scene without cells, or for horizon on a scene
    /// without box occluders.
    SceneOcclusion(const Scene& scene, const SceneObjectLevel& level, SceneOcclusionMethod method);

    /// One frame after SceneObjectLevel::cull (its boxes and result): the spans of `result` plus
    /// those of the objects the method hides. Valid until the next call.
    const ObjectCullResult& cull(const ObjectCullResult& result, const Camera& camera, int width, int height);

    SceneOcclusionMethod method() const { return method_; }
    const SceneOcclusionStats& stats() const { return stats_; }
    /// Per object (SceneObjectLevel order) after cull: 1 when this method hid it.
    const std::vector<std::uint8_t>& hidden() const { return hidden_; }
    std::size_t occluder_count() const { return occluder_objects_.size(); }

private:
    bool near_pyramid_touches_environment(const Mat4& world_to_clip, Vec3 eye) const;
    const Scene* scene_;
    const SceneObjectLevel* level_;
    SceneOcclusionMethod method_;
    std::vector<std::size_t> occluder_objects_;  // object indices of the box occluders
    std::vector<Bounds> occluder_boxes_, tested_boxes_;
    std::vector<std::size_t> tested_objects_;
    std::vector<std::uint8_t> occluded_, hidden_;
    OcclusionHorizon horizon_;
    std::unique_ptr<PortalCuller> portals_;
    ObjectCullResult out_;
    SceneOcclusionStats stats_;
};

/// Sorts spans and merges overlapping or touching ones (in place): ascending and disjoint, as
/// ObjectCullResult's spans are.
void merge_spans(std::vector<IndexSpan>& spans);

/// CHC++'s tight bounding volumes (tight_bounds.h) of a scene's instances, for
/// gl::FrameObjects::tight: per instance a TightBounds over its patches' boxes (the 16 control
/// points' AABB, grown by the patch's max |D| where displaced; built from the first pose given),
/// refitted to each pose. Each instance's selected boxes hold all its patches' boxes, so
/// everything it draws.
/// Tight boxes per object when no count is asked for (render's chc++, eval scene's
/// --max-tight-boxes default): the cap the sigma rule stops at.
inline constexpr std::size_t kDefaultMaxTightBoxes = 16;

class SceneTightBounds {
public:
    /// pose: a pose of every instance (ScenePoser::pose), ranges: its displacement ranges (empty:
    /// undisplaced).
    SceneTightBounds(const Scene& scene, const std::vector<BezierPatch>& pose,
                     const std::vector<DisplacementRange>& ranges);
    /// Refits to a pose of the same scene and selects each instance's boxes (TightBounds::select
    /// with sigma and max_boxes).
    void update(const std::vector<BezierPatch>& pose, const std::vector<DisplacementRange>& ranges, float sigma,
                std::size_t max_boxes);
    /// Instance i's boxes: boxes()[first()[i] .. first()[i + 1]).
    const std::vector<Bounds>& boxes() const { return tight_; }
    const std::vector<std::uint32_t>& first() const { return tight_first_; }

private:
    void patch_boxes(const std::vector<BezierPatch>& pose, const std::vector<DisplacementRange>& ranges);
    std::vector<Bounds> boxes_, tight_;
    std::vector<std::uint32_t> tight_first_;
    std::vector<std::size_t> firsts_;
    std::vector<TightBounds> trees_;
};

}  // namespace patchcull

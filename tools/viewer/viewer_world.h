// What the viewer draws (`patchcull view`): the scene with the displacement and the object level
// the settings ask for, posed and uploaded to the pipeline. Turning displacement on or off, its
// scale, or the object-level method rebuilds it from the loaded scene (the poser's displacement
// ranges and the object level's clusters are computed at construction); the pipeline's statuses
// then restart (a first frame).
#pragma once

#include <memory>
#include <vector>

#include "object_level_options.h"
#include "patchcull/gl/gl_pipeline.h"
#include "patchcull/import/scene_poser.h"
#include "viewer_settings.h"

namespace patchcull::cli {

class ViewerWorld {
public:
    /// base: the loaded scene after --displace (its map, if any, is the one `displace on` uses;
    /// without one, `displace on` displaces every instance with the procedural map). options: the
    /// command's object-level flags (checked by the first build; later builds change the method).
    ViewerWorld(Scene base, ObjectLevelOptions options);

    /// Displacement on, and its scale, as the loaded scene has it (0.02 without a map).
    bool base_displaced() const { return !base_.displacement.empty(); }
    float base_displace_scale() const { return base_displaced() ? base_.displacement.scale : 0.02f; }

    /// True when settings ask for another displacement or object level than the last build.
    bool needs_build(const ViewerSettings& settings) const;
    /// Builds the scene for settings (CPU only, so the first build checks the object-level flags
    /// before a window opens: it may throw patchcull::Error naming one) and poses it at
    /// time_seconds; upload() then gives it to the pipeline.
    void build(const ViewerSettings& settings, float time_seconds);
    /// After a build: uploads the pose (fresh statuses), the displacement map and the occluders.
    void upload(gl::CullPipeline& pipeline);
    /// Poses the scene at time_seconds and uploads the patches (statuses kept).
    void pose(float time_seconds, gl::CullPipeline& pipeline);

    const Scene& scene() const { return *scene_; }
    const ScenePoser& poser() const { return *poser_; }
    const std::vector<BezierPatch>& current_pose() const { return *pose_; }
    ObjectLevelRun& object_level() { return *object_level_; }
    /// One range per instance (scene_objects), for --cull auto.
    const std::vector<gl::ObjectRange>& ranges() const { return ranges_; }
    const std::vector<std::string>& names() const { return names_; }
    bool one_sided() const { return one_sided_; }

private:
    Scene base_;
    ObjectLevelOptions options_;
    std::unique_ptr<Scene> scene_;
    std::unique_ptr<ObjectLevelRun> object_level_;
    std::unique_ptr<ScenePoser> poser_;
    const std::vector<BezierPatch>* pose_ = nullptr;
    std::vector<gl::ObjectRange> ranges_;
    std::vector<std::string> names_;
    bool one_sided_ = false;
    bool built_ = false;
    bool built_displace_ = false;
    float built_scale_ = 0;
    std::string built_objects_;
};

}  // namespace patchcull::cli

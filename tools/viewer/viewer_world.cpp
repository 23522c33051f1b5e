// The viewer's scene, rebuilt when displacement or the object level change (viewer_world.h).
#include "viewer_world.h"

#include "patchcull/eval_gl/scene_setup.h"

namespace patchcull::cli {

ViewerWorld::ViewerWorld(Scene base, ObjectLevelOptions options)
    : base_(std::move(base)), options_(std::move(options)) {}

bool ViewerWorld::needs_build(const ViewerSettings& s) const {
    return !built_ || s.displace != built_displace_ || (s.displace && s.displace_scale != built_scale_) ||
           s.objects != built_objects_;
}

void ViewerWorld::build(const ViewerSettings& s, float time_seconds) {
    // The poser and the object level point into the scene: gone before it is replaced.
    poser_.reset();
    object_level_.reset();
    auto scene = std::make_unique<Scene>(base_);
    if (!s.displace) {
        scene->displacement = {};
        scene->displacement_name = "none";
        for (SceneInstance& instance : scene->instances) instance.displaced = false;
    } else if (base_displaced()) {
        scene->displacement.scale = s.displace_scale;  // the heights stay; D = scale * (h - midlevel)
    } else {
        scene->displacement = make_procedural_displacement(512, s.displace_scale);
        scene->displacement_name = "procedural";
        for (SceneInstance& instance : scene->instances) instance.displaced = true;
    }
    one_sided_ = eval_gl::scene_is_one_sided(*scene);
    ObjectLevelOptions options = options_;
    if (built_) {
        // The command's flags were checked by the first build; later ones change the method only.
        options.given.clear();
        options.method = s.objects;
        if (options.method == "none") options.detail_pixels = 0;
    }
    object_level_ = std::make_unique<ObjectLevelRun>(options, *scene, one_sided_);  // before the occluders go up
    scene_ = std::move(scene);
    poser_ = std::make_unique<ScenePoser>(*scene_);
    pose_ = &poser_->pose(time_seconds);  // before pose_attributes reads it
    ranges_.clear();
    names_.clear();
    for (const eval_gl::SceneObject& o : eval_gl::scene_objects(*scene_))
        ranges_.push_back(o.range), names_.push_back(o.name);
    built_ = true;
    built_displace_ = s.displace;
    built_scale_ = s.displace_scale;
    built_objects_ = s.objects;
}

void ViewerWorld::upload(gl::CullPipeline& pipeline) {
    pipeline.set_patches(*pose_, eval_gl::pose_attributes(*poser_));
    pipeline.renderer().set_displacement_map(scene_->displacement);
    eval_gl::upload_scene_occluders(pipeline.renderer(), *scene_);
}

void ViewerWorld::pose(float time_seconds, gl::CullPipeline& pipeline) {
    pose_ = &poser_->pose(time_seconds);
    pipeline.update_patches(*pose_, eval_gl::pose_attributes(*poser_));
}

}  // namespace patchcull::cli

// patchcull/import/default_scene.h: the former header of scenes, now scene_model.h (the Scene),
// builtin_scenes.h (the built-in scenes) and scene_poser.h (ScenePoser); it includes all three.
#pragma once

#include "patchcull/import/builtin_scenes.h"
#include "patchcull/import/scene_model.h"
#include "patchcull/import/scene_poser.h"

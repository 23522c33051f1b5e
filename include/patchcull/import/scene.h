// patchcull/import/scene.h: the former name of model_loader.h (it includes it).
#pragma once

#include "patchcull/import/model_loader.h"

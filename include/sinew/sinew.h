// Sinew: ray-traced skinned characters as one pass of a host engine's frame
// (docs/EMBEDDING.md). Load baked content packs (Character), place and
// animate instances (World), render them (RayTracePass).
#pragma once

#include "sinew/character.h"
#include "sinew/math.h"
#include "sinew/pass.h"
#include "sinew/result.h"
#include "sinew/tasks.h"
#include "sinew/version.h"
#include "sinew/view.h"
#include "sinew/world.h"

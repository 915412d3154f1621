// Reading the [fiber] table of a scene into a fiber::Config, strictly: every key is checked for
// type and range and every table is finished (unknown keys are errors with a "did you mean").
// The keys are documented in fiber/README.md.
#pragma once

#include "scene.hpp"
#include "spec.hpp"

namespace fiber {

// Throws fsi::InputError naming the key, the value and the file:line.
Config read_config(const fsi::SceneTable& fiber);

// Checks the scene can hold the attached roots: without a solid solver (no [solid] section) an
// attached root has nothing to hold it. `fiber` is the [fiber] table the config was read from.
// Whether the named body exists and the point lies on its surface is the coupler's to check.
void check_attachments(const Config& config, const fsi::SceneTable& fiber, bool has_solid);

// Throws fsi::InputError when time.dt (divided by fiber.substeps) is above the explicit bending
// limit of a fiber; the message states the limit.
void check_time_step(const Config& config, double dt);

}  // namespace fiber

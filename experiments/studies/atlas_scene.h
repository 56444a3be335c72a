// The crossover atlas's scenes (atlas.h): the cube thrown and falling onto the floor, thrown in
// free flight, or thrown down an incline with friction; the contact of its floor or incline; and
// the fastest frequency of each, contact (and static friction) included, which sets the RK4
// reference's step and the explicit methods' first step tried.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "src/world/world.h"

namespace jello::experiments {

// The atlas's scenes: `falling` (the default) is the cube thrown sideways and spinning, falling
// onto the floor under gravity and bouncing; `free` the same throw and spin without gravity,
// which touches nothing within the window: only rigid motion and what the spin stretches;
// `slide` (issue 39, the friction scene) the cube thrown down a 20 degree incline with Coulomb
// friction mu = 0.6 (> tan 20 degrees), landing, sliding and coming to rest on it within its
// 2 s window (kSlideTime).
enum class AtlasScene { Falling, Free, Slide };
std::optional<AtlasScene> parseAtlasScene(const std::string& name);
std::string sceneName(AtlasScene scene);  // as parseAtlasScene reads it
std::vector<std::string> sceneNames();
std::string describe(AtlasScene scene);
inline constexpr double kSlideTime = 2.0;  // s, the slide scene's window
// The slide scene's incline: its normal (pointing out of the solid) and downhill direction.
Vec3 slideNormal();
Vec3 slideDownhill();
// The floor's contact in the falling scene (issue 39, contact stiffness as an axis), the
// incline's in the slide scene: penalty springs of the course's kCollision = 400 N/m (`soft`, the
// default), as stiff as the lattice's springs (`k`), or 20 k (`20k`, as the stability map's
// wall scene); or IPC's log barrier (`barrier`: kappa = k, dhat 5 mm), which no point crosses.
enum class AtlasContact { Soft, AsStiff, Stiffer, Barrier };
std::optional<AtlasContact> parseAtlasContact(const std::string& name);
std::string contactName(AtlasContact contact);  // as parseAtlasContact reads it
std::vector<std::string> contactNames();
double contactStiffness(AtlasContact contact, double k);  // N/m: kCollision (barrier: kappa)
// The name stored references are kept under: the scene's ("falling", "free"), with the
// contact's after it unless soft ("falling-contact-20k"), so the soft atlas's stay valid.
std::string referenceSceneName(AtlasScene scene, AtlasContact contact);

// The scene at stiffness k (c = 0.25 N*s/m), N^3 points of 1/512 kg (w_max does not depend on N).
World atlasScene(double k, int n, AtlasScene scene = AtlasScene::Falling,
                 AtlasContact contact = AtlasContact::Soft);

// w_max of the scene, contact included: the larger of the lattice's at the start and the cube's
// resting on the floor (its bottom face 1 mm inside it, every bottom point on a contact spring:
// the stiffest the contact makes it). The free scene touches nothing: the start's alone. The
// slide scene's cube rests on the incline instead, and static friction's damper adds its rate
// 2 mu lambda / (m eps) (src/PHYSICS.md, "Friction"), lambda bounded by twice the weight of a
// column of N points.
double atlasMaxFrequency(const World& w, AtlasScene scene);

}  // namespace jello::experiments

#pragma once
// The colliders in files: the one JSON form of a collider (docs/scenario-format.md, "colliders"),
// read by the scenario reader and the result readers, written by the result writers
// (docs/result-format.md), so that a result carries its run's colliders as its scenario gave them.
// Private to the library; implemented in io/scenario_colliders.cc beside the scenario's reader.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/error.h"

namespace flexkin {

// A "colliders" array in `dim` dimensions (2D shapes in the plane z = 0), read as a scenario's is;
// every problem is appended to `problems`, named by JSON pointer under `ptr`
// ("/colliders/1/radius"). A mesh's relative "file" is read from `directory` ("": the working
// directory); a mesh given inline ("vertices", "triangles", as result files carry it) reads none.
// A keyframed collider's "motion" has its times in `time_unit` (chains: "leader steps"; grooms
// and strand files: "seconds").
std::vector<Collider> ReadCollidersJson(const nlohmann::json& v, const std::string& ptr, int dim,
                                        Problems* problems, const std::string& directory = "",
                                        const char* time_unit = "leader steps");

// The problems of colliders to be written in `dim` dimensions, fields "colliders[k]...": those of
// CheckCollider, and, in 2D, a collider that the 2D form cannot say (a centre off the plane z = 0,
// an axis, a normal or a rotation that leaves it).
Problems CollidersProblems(const std::vector<Collider>& colliders, int dim);

// One collider as a JSON object of the scenario form, on one line, numbers with 17 significant
// digits: {"shape": "capsule", "from": [..], "to": [..], "radius": r}. `collider` passes
// CollidersProblems in `dim`.
void AppendColliderJson(const Collider& collider, int dim, std::string* out);

}  // namespace flexkin

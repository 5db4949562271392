// The "colliders" of a chain scenario (docs/scenario-format.md, docs/colliders.md): each shape in
// the chain's dimension (2D shapes lie in the plane z = 0), read into a Collider placed by a pose;
// and the same form written back from a Collider, for result files (io/colliders_json.h).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "flexkin/scenario.h"
#include "io/colliders_json.h"
#include "io/result_writers.h"
#include "io/scenario_parser.h"

namespace flexkin::scenario_internal {
namespace {

Eigen::Vector3d In3d(const Eigen::VectorXd& v) {
  return Eigen::Vector3d(v[0], v[1], v.size() == 3 ? v[2] : 0.0);
}

// The rotation that takes the frame's z axis to `axis` (nonzero).
Eigen::Matrix3d ZAxisAlong(const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).toRotationMatrix();
}

}  // namespace

void Parser::ParseColliders(const json& v, const std::string& ptr, int dim,
                            std::vector<Collider>* colliders, const char* whose) {
  if (!v.is_array()) {
    TypeProblem(v, ptr, "an array of colliders, e.g. [{\"shape\": \"sphere\", ...}]");
    return;
  }
  dimension_of_ = whose;
  for (size_t i = 0; i < v.size(); ++i) {
    if (auto c = ParseCollider(v[i], ptr + "/" + std::to_string(i), dim)) {
      colliders->push_back(*c);
    }
  }
}

std::optional<Collider> Parser::ParseCollider(const json& v, const std::string& ptr, int dim) {
  static const std::vector<std::string> kShapes = {"sphere", "ellipsoid",  "capsule", "cylinder",
                                                   "box",    "half_space", "mesh"};
  if (!ExpectObject(v, ptr, "an object {\"shape\": ..., ...}")) return std::nullopt;
  const json* shape_value = Required(v, ptr, "shape", "one of " + QuotedList(kShapes));
  if (shape_value == nullptr) return std::nullopt;
  const auto shape = String(*shape_value, ptr + "/shape");
  if (!shape) return std::nullopt;
  if (std::find(kShapes.begin(), kShapes.end(), *shape) == kShapes.end()) {
    problems.push_back(UnknownName(ptr + "/shape", "collider shape", *shape, kShapes));
    return std::nullopt;
  }
  const size_t before = problems.size();
  Collider c;
  const auto vector = [&](const char* key) -> std::optional<Eigen::VectorXd> {
    const json* x = Required(v, ptr, key, "an array of " + std::to_string(dim) + " numbers");
    return x != nullptr ? Vector(*x, ptr + "/" + key, dim) : std::nullopt;
  };
  const auto positive = [&](const char* key) {
    double value = 0.0;
    Require(
        v, ptr, key, "a finite number > 0",
        [&](const json& x, const std::string& p) { return Number(x, p, Range::kPositive); },
        &value);
    return value;
  };
  // The orientation of a box or an ellipsoid: "angle" (2D, radians about z) or "rotation" (3D, a
  // unit quaternion [w, x, y, z]); axis-aligned without one.
  const auto orientation = [&]() {
    if (dim == 2) {
      double angle = 0.0;
      Optional(
          v, ptr, "angle",
          [&](const json& x, const std::string& p) { return Number(x, p, Range::kAny); }, &angle);
      c.pose.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    } else if (const json* r = Find(v, "rotation")) {
      if (const auto q = Vector(*r, ptr + "/rotation", 4)) {
        const double norm = q->norm();
        if (!(norm > 0.0)) {
          Add(ptr + "/rotation",
              "is not a rotation; expected a quaternion [w, x, y, z] of length 1", ShowJson(*r),
              "a unit quaternion [w, x, y, z]");
        } else if (std::fabs(norm - 1.0) > 1e-9) {
          Add(ptr + "/rotation",
              "has length " + FormatNumber(norm) + "; expected a unit quaternion [w, x, y, z]",
              ShowJson(*r), "a unit quaternion [w, x, y, z]");
        } else {
          c.pose.linear() = Eigen::Quaterniond((*q)[0], (*q)[1], (*q)[2], (*q)[3])
                                .normalized()
                                .toRotationMatrix();
        }
      }
    }
  };
  // The extents of a box or an ellipsoid: `dim` positive numbers (a 2D shape's third is 1, which
  // its slice by the plane z = 0 does not see).
  const auto extents = [&](const char* key) {
    if (const auto e = vector(key)) {
      for (int k = 0; k < dim; ++k) {
        if (!((*e)[k] > 0.0)) {
          Add(ptr + "/" + key + "/" + std::to_string(k),
              "value " + FormatNumber((*e)[k]) + " is not valid; expected a finite number > 0",
              FormatNumber((*e)[k]), "a finite number > 0");
        }
        c.extents[k] = (*e)[k];
      }
      if (dim == 2) c.extents[2] = 1.0;
    }
  };
  std::vector<std::string> keys = {"shape"};
  if (*shape == "sphere") {
    c.shape = ColliderShape::kSphere;
    keys.insert(keys.end(), {"center", "radius"});
    if (const auto center = vector("center")) c.pose.translation() = In3d(*center);
    c.radius = positive("radius");
  } else if (*shape == "capsule" || *shape == "cylinder") {
    c.shape = *shape == "capsule" ? ColliderShape::kCapsule : ColliderShape::kCylinder;
    keys.insert(keys.end(), {"from", "to", "radius"});
    const auto from = vector("from"), to = vector("to");
    c.radius = positive("radius");
    if (from && to) {
      const Eigen::Vector3d a = In3d(*from), b = In3d(*to);
      c.pose.translation() = 0.5 * (a + b);
      c.half_length = 0.5 * (b - a).norm();
      if (c.half_length > 0.0) {
        c.pose.linear() = ZAxisAlong(b - a);
      } else if (c.shape == ColliderShape::kCylinder) {
        Add(ptr + "/to", "equals \"from\"; a cylinder needs an axis of positive length",
            ShowJson(v["to"]), "a point other than \"from\"");
      }
    }
  } else if (*shape == "box" || *shape == "ellipsoid") {
    const bool box = *shape == "box";
    c.shape = box ? ColliderShape::kBox : ColliderShape::kEllipsoid;
    const char* size_key = box ? "half_extents" : "semi_axes";
    keys.insert(keys.end(), {"center", size_key, "angle", "rotation"});
    const char* other = dim == 2 ? "rotation" : "angle";
    if (Find(v, other) != nullptr) {
      Add(ptr + "/" + other,
          dim == 2 ? "is for 3D shapes; a 2D shape turns by \"angle\" (radians about z)"
                   : "is for 2D shapes; a 3D shape turns by \"rotation\" (a unit quaternion "
                     "[w, x, y, z])");
    }
    if (const auto center = vector("center")) c.pose.translation() = In3d(*center);
    extents(size_key);
    orientation();
  } else if (*shape == "mesh") {
    c.shape = ColliderShape::kMesh;
    keys.insert(keys.end(), {"file", "scale", "position", "rotation", "vertices", "triangles"});
    if (dim != 3) {
      Add(ptr + "/shape",
          "is a 3D shape; a 2D chain's colliders are its sections by the plane z = 0, which a "
          "mesh does not give",
          "\"mesh\"",
          "one of \"sphere\", \"ellipsoid\", \"capsule\", \"cylinder\", \"box\", "
          "\"half_space\"");
      return std::nullopt;
    }
    ParseMesh(v, ptr, &c);
    orientation();
  } else {
    c.shape = ColliderShape::kHalfSpace;
    keys.insert(keys.end(), {"point", "normal"});
    if (const auto point = vector("point")) c.pose.translation() = In3d(*point);
    if (const auto normal = vector("normal")) {
      if (normal->norm() > 0.0) {
        c.pose.linear() = ZAxisAlong(In3d(*normal));
      } else {
        Add(ptr + "/normal", "is zero; expected the outward normal of the half-space's plane",
            ShowJson(v["normal"]), "a nonzero vector");
      }
    }
  }
  keys.push_back("motion");
  CheckKeys(v, ptr, keys);
  // A keyframed collider (docs/colliders.md, "Moving colliders"): times in leader steps.
  if (const json* m = Find(v, "motion")) {
    const std::string mp = ptr + "/motion";
    if (ExpectObject(*m, mp, "an object {\"keyframes\": [...], \"interpolation\": \"smooth\"}")) {
      CheckKeys(*m, mp, {"interpolation", "keyframes"});
      if (auto keys = ReadKeyframes(*m, mp, dim, motion_time_unit, kMaxLeaderSteps)) {
        auto motion = std::make_shared<ColliderMotion>();
        motion->keyframes = std::move(keys->first);
        motion->interpolation = keys->second;
        c.motion = std::move(motion);
      }
    }
  }
  if (problems.size() != before) return std::nullopt;
  return c;
}

void Parser::ParseMesh(const json& v, const std::string& ptr, Collider* c) {
  if (const json* x = Find(v, "position")) {
    if (const auto p = Vector(*x, ptr + "/position", 3)) c->pose.translation() = *p;
  }
  Optional(
      v, ptr, "scale",
      [&](const json& x, const std::string& p) { return Number(x, p, Range::kPositive); },
      &c->scale);
  std::string file;
  const json* file_value = Find(v, "file");
  if (file_value != nullptr) {
    const auto name = String(*file_value, ptr + "/file");
    if (!name) return;
    if (name->empty()) {
      Add(ptr + "/file", "is empty; expected the path of an STL or OBJ file", "\"\"",
          "a path, relative to the scenario file's directory");
      return;
    }
    file = *name;
  }
  // A result file carries the mesh itself (io/colliders_json.h): "vertices" and "triangles".
  const json* vertices_value = Find(v, "vertices");
  if (vertices_value != nullptr || Find(v, "triangles") != nullptr) {
    const json* t = Required(v, ptr, "triangles", "an array of [i, j, k] vertex indices");
    const json* p = Required(v, ptr, "vertices", "an array of [x, y, z] points");
    if (t == nullptr || p == nullptr) return;
    const auto points = JsonReader::PointList(*p, ptr + "/vertices", 3, 0, int64_t{1} << 26);
    if (!t->is_array()) {
      TypeProblem(*t, ptr + "/triangles", "an array of [i, j, k] vertex indices");
      return;
    }
    MeshTriangles triangles(static_cast<Eigen::Index>(t->size()), 3);
    const size_t before = problems.size();
    for (size_t f = 0; f < t->size(); ++f) {
      const std::string at = ptr + "/triangles/" + std::to_string(f);
      if (!(*t)[f].is_array() || (*t)[f].size() != 3) {
        TypeProblem((*t)[f], at, "an array of 3 vertex indices");
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        const auto i = Integer((*t)[f][k], at + "/" + std::to_string(k), 0, (int64_t{1} << 31) - 1);
        triangles(static_cast<Eigen::Index>(f), k) = i ? static_cast<int>(*i) : 0;
      }
    }
    if (!points || problems.size() != before) return;
    // An empty list reads as 0 by 0: the mesh's own check names it.
    MeshVertices vertices = points->rows() > 0 ? MeshVertices(*points) : MeshVertices(0, 3);
    c->mesh = MakeColliderMesh(std::move(vertices), std::move(triangles), file, ptr + "/vertices",
                               &problems);
    return;
  }
  if (file_value == nullptr) {
    Add(ptr + "/file", "missing; expected the path of an STL or OBJ file", "",
        "a path, relative to the scenario file's directory");
    return;
  }
  const std::filesystem::path path(file);
  const std::string full = path.is_absolute() || directory.empty()
                               ? file
                               : (std::filesystem::path(directory) / path).string();
  c->mesh = ReadColliderMeshFile(full, file, ptr + "/file", &problems);
}

}  // namespace flexkin::scenario_internal

namespace flexkin {
namespace {

// How far off the plane z = 0 a 2D collider's numbers may be (rounding of its pose).
constexpr double kPlaneTolerance = 1e-9;

void AppendPoint(const Eigen::Vector3d& p, int dim, std::string* out) {
  out->push_back('[');
  for (int k = 0; k < dim; ++k) {
    if (k > 0) out->append(", ");
    AppendJsonDouble(p[k], out);
  }
  out->push_back(']');
}

void AppendKey(const char* key, std::string* out) {
  out->append(", \"");
  out->append(key);
  out->append("\": ");
}

}  // namespace

std::vector<Collider> ReadCollidersJson(const nlohmann::json& v, const std::string& ptr, int dim,
                                        Problems* problems, const std::string& directory,
                                        const char* time_unit) {
  scenario_internal::Parser parser;
  parser.directory = directory;
  parser.motion_time_unit = time_unit;
  std::vector<Collider> colliders;
  parser.ParseColliders(v, ptr, dim, &colliders, "the result");
  problems->insert(problems->end(), parser.problems.begin(), parser.problems.end());
  return colliders;
}

Problems CollidersProblems(const std::vector<Collider>& colliders, int dim) {
  Problems problems;
  for (size_t k = 0; k < colliders.size(); ++k) {
    const Collider& c = colliders[k];
    const std::string field = "colliders[" + std::to_string(k) + "]";
    const size_t before = problems.size();
    for (Problem& p : CheckCollider(c, field)) problems.push_back(std::move(p));
    if (problems.size() != before || dim != 2) continue;
    const Eigen::Vector3d t = c.pose.translation(), z = c.pose.linear().col(2);
    const bool axis_in_plane = std::fabs(z.z()) <= kPlaneTolerance;  // capsule, cylinder, floor
    bool in_plane = std::fabs(t.z()) <= kPlaneTolerance * (1.0 + t.norm());
    switch (c.shape) {
      case ColliderShape::kSphere:
        break;
      case ColliderShape::kCapsule:
        in_plane = in_plane && (c.half_length == 0.0 || axis_in_plane);
        break;
      case ColliderShape::kCylinder:
      case ColliderShape::kHalfSpace:
        in_plane = in_plane && axis_in_plane;
        break;
      case ColliderShape::kBox:
      case ColliderShape::kEllipsoid:  // turned about z only
        in_plane = in_plane && std::fabs(z.z() - 1.0) <= kPlaneTolerance;
        break;
      case ColliderShape::kMesh:
        problems.emplace_back(field,
                              "is a mesh, a 3D shape; a 2D result's colliders are "
                              "sections by the plane z = 0, which a mesh does not give");
        continue;
    }
    if (!in_plane) {
      problems.emplace_back(field,
                            std::string("is a ") + ColliderShapeName(c.shape) +
                                " that does not lie in the plane z = 0; a 2D result's colliders "
                                "are written in the 2D form of a scenario's (docs/"
                                "scenario-format.md), centred in that plane, their axes and "
                                "normals in it, turned about z only");
    }
    if (!c.motion) continue;
    // A 2D motion moves in the plane and turns about z only ("angle_deg").
    for (size_t i = 0; i < c.motion->keyframes.size(); ++i) {
      const BodyPose& p = c.motion->keyframes[i].pose;
      if (std::fabs(p.translation.z()) > kPlaneTolerance * (1.0 + p.translation.norm()) ||
          std::fabs(p.rotation(2, 2) - 1.0) > kPlaneTolerance) {
        problems.emplace_back(field + ".motion.keyframes[" + std::to_string(i) + "]",
                              "leaves the plane z = 0; a 2D result's keyframes move in that "
                              "plane and turn about z only");
      }
    }
  }
  return problems;
}

void AppendColliderJson(const Collider& c, int dim, std::string* out) {
  const Eigen::Vector3d t = c.pose.translation();
  const Eigen::Matrix3d r = c.pose.linear();
  out->append("{\"shape\": \"");
  out->append(ColliderShapeName(c.shape));
  out->push_back('"');
  const auto point = [&](const char* key, const Eigen::Vector3d& p) {
    AppendKey(key, out);
    AppendPoint(p, dim, out);
  };
  const auto number = [&](const char* key, double x) {
    AppendKey(key, out);
    AppendJsonDouble(x, out);
  };
  const auto rotation = [&]() {
    Eigen::Quaterniond q(r);
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    AppendKey("rotation", out);
    const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
    for (int k = 0; k < 4; ++k) {
      out->append(k == 0 ? "[" : ", ");
      AppendJsonDouble(wxyz[k], out);
    }
    out->push_back(']');
  };
  switch (c.shape) {
    case ColliderShape::kSphere:
      point("center", t);
      number("radius", c.radius);
      break;
    case ColliderShape::kCapsule:
    case ColliderShape::kCylinder:
      point("from", t - c.half_length * r.col(2));
      point("to", t + c.half_length * r.col(2));
      number("radius", c.radius);
      break;
    case ColliderShape::kBox:
    case ColliderShape::kEllipsoid:
      point("center", t);
      point(c.shape == ColliderShape::kBox ? "half_extents" : "semi_axes", c.extents);
      if (r.isIdentity(0.0)) break;  // axis-aligned: as a scenario without "angle" says it
      if (dim == 2) {
        number("angle", std::atan2(r(1, 0), r(0, 0)));
      } else {
        rotation();
      }
      break;
    case ColliderShape::kHalfSpace:
      point("point", t);
      point("normal", r.col(2));
      break;
    case ColliderShape::kMesh: {
      // The mesh itself, beside its file's name: a result file stands alone (it is read, drawn
      // and checked where the mesh file is not, and a later edit of that file does not change
      // what the run met). A reader takes the inline mesh and never opens the file.
      const ColliderMeshData& m = *c.mesh;
      if (!m.file.empty()) {
        AppendKey("file", out);
        out->append(nlohmann::json(m.file).dump());
      }
      number("scale", c.scale);
      point("position", t);
      rotation();
      AppendKey("vertices", out);
      for (Eigen::Index i = 0; i < m.vertices.rows(); ++i) {
        out->append(i == 0 ? "[" : ", ");
        AppendPoint(m.vertices.row(i).transpose(), 3, out);
      }
      out->push_back(']');
      AppendKey("triangles", out);
      for (Eigen::Index f = 0; f < m.triangles.rows(); ++f) {
        out->append(f == 0 ? "[[" : ", [");
        for (int k = 0; k < 3; ++k) {
          if (k > 0) out->append(", ");
          out->append(std::to_string(m.triangles(f, k)));
        }
        out->push_back(']');
      }
      out->push_back(']');
      break;
    }
  }
  if (c.motion) {
    AppendKey("motion", out);
    out->append("{\"interpolation\": \"");
    out->append(c.motion->interpolation == KeyframeInterpolation::kLinear ? "linear" : "smooth");
    out->append("\", \"keyframes\": [");
    for (size_t k = 0; k < c.motion->keyframes.size(); ++k) {
      const BodyKeyframe& key = c.motion->keyframes[k];
      if (k > 0) out->append(", ");
      out->append("{\"time\": ");
      AppendJsonDouble(key.time, out);
      AppendKey("translation", out);
      AppendPoint(key.pose.translation, dim, out);
      if (dim == 2) {
        AppendKey("angle_deg", out);
        AppendJsonDouble(std::atan2(key.pose.rotation(1, 0), key.pose.rotation(0, 0)) *
                             (180.0 / 3.14159265358979323846),
                         out);
      } else {
        Eigen::Quaterniond q(key.pose.rotation);
        if (q.w() < 0.0) q.coeffs() = -q.coeffs();
        out->append(", \"rotation\": {\"quaternion\": ");
        const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
        for (int i = 0; i < 4; ++i) {
          out->append(i == 0 ? "[" : ", ");
          AppendJsonDouble(wxyz[i], out);
        }
        out->append("]}");
      }
      out->push_back('}');
    }
    out->append("]}");
  }
  out->push_back('}');
}

std::vector<Collider> ParseCollidersText(const std::string& json_text, int dim) {
  nlohmann::json v;
  try {
    v = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError("/colliders", std::string("is not valid JSON: ") + e.what());
  }
  if (dim == 0) {
    dim = 3;
    if (v.is_array() && !v.empty() && v[0].is_object()) {
      for (const char* key : {"center", "from", "point", "position"}) {
        const auto it = v[0].find(key);
        if (it != v[0].end() && it->is_array() && (it->size() == 2 || it->size() == 3)) {
          dim = static_cast<int>(it->size());
          break;
        }
      }
    }
  }
  Problems problems;
  std::vector<Collider> colliders = ReadCollidersJson(v, "/colliders", dim, &problems);
  ThrowIfAny(problems);
  return colliders;
}

std::string CollidersText(const std::vector<Collider>& colliders, int dim) {
  ThrowIfAny(CollidersProblems(colliders, dim));
  std::string out = "[";
  for (size_t k = 0; k < colliders.size(); ++k) {
    if (k > 0) out += ", ";
    AppendColliderJson(colliders[k], dim, &out);
  }
  return out + "]";
}

}  // namespace flexkin

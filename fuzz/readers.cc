#include "readers.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>

#include "flexkin/any_scenario.h"
#include "flexkin/error.h"
#include "flexkin/gltf.h"
#include "flexkin/groom.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/scenario.h"
#include "flexkin/strand_file.h"
#include "flexkin/tree_scenario.h"
#include "flexkin/urdf.h"

namespace flexkin::fuzz {
namespace {

// A spatial arm of three joints (yaw, pitch, roll) and a fixed tool frame: the arm of every robot
// scenario that names a URDF file.
const char* kUrdf = R"(<robot name="three"><link name="base_link"/><link name="a"/><link name="b"/>
<link name="c"/><link name="tip_link"/>
<joint name="yaw" type="revolute"><parent link="base_link"/><child link="a"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="pitch" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0 0 0.3"/>
<axis xyz="0 1 0"/></joint>
<joint name="roll" type="continuous"><parent link="b"/><child link="c"/><origin xyz="0.2 0 0"/>
<axis xyz="1 0 0"/></joint>
<joint name="tool" type="fixed"><parent link="c"/><child link="tip_link"/><origin xyz="0.1 0 0"/>
</joint></robot>)";

// `bytes` written to a file in a directory of this process's own (made once, removed at exit),
// so that a glTF file's relative buffer URIs find nothing else.
std::string WriteTemporary(const std::string& bytes, const char* name) {
  // Never destroyed: the atexit handler runs after the destructors of statics made before it.
  static const std::filesystem::path* const dir = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "flexkin-fuzz-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::system_error(errno, std::generic_category(), pattern);
    auto* made = new std::filesystem::path(pattern);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(*dir, ignored);
    });
    return made;
  }();
  const std::string path = (*dir / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::system_error(EIO, std::generic_category(), path);
  return path;
}

// Validate and Parse of one kind of scenario must agree: no problems if and only if it parses.
// Else std::logic_error, which no reader throws: a finding.
template <typename Validate, typename Parse>
void ValidateThenParse(const Validate& validate, const Parse& parse) {
  const Problems problems = validate();
  bool parsed = false;
  try {
    parse();
    parsed = true;
  } catch (const InputError&) {
    if (problems.empty()) throw;  // escapes as a finding below
  }
  if (parsed != problems.empty()) {
    throw std::logic_error("validate found " + std::to_string(problems.size()) + " problems (" +
                           (problems.empty() ? "" : problems.front().message) + ") but parse " +
                           (parsed ? "succeeded" : "failed"));
  }
}

}  // namespace

void ReadScenario(const std::string& bytes) {
  ValidateThenParse([&] { return ValidateScenarioText(bytes); }, [&] { ParseScenarioText(bytes); });
}

void ReadRobotScenario(const std::string& bytes) {
  RobotScenarioOptions options;
  options.urdf_loader = [](const std::string&, const UrdfChain& chain) {
    return ArmFromUrdf(kUrdf, chain);
  };
  IsRobotScenarioText(bytes);
  ValidateThenParse([&] { return ValidateRobotScenarioText(bytes, options); },
                    [&] { ParseRobotScenarioText(bytes, options); });
}

void ReadGroomScenario(const std::string& bytes) {
  IsGroomText(bytes);
  // A grown groom holds roots x (links + 1) points (up to kMaxGroomPoints, 4.8 GB): over the
  // fuzzer's memory limit. Validation reads any size; growing, only up to a million points.
  const nlohmann::json root = nlohmann::json::parse(bytes, nullptr, /*allow_exceptions=*/false);
  if (root.is_object() && root.contains("groom") && root["groom"].is_object()) {
    const nlohmann::json& groom = root["groom"];
    const auto count = [&](const char* key) {
      const auto it = groom.find(key);
      return it != groom.end() && it->is_number() ? it->get<double>() : 0.0;
    };
    if (count("roots") * (count("links") + 1.0) > 1e6) {
      ValidateGroomText(bytes);
      return;
    }
  }
  ValidateThenParse([&] { return ValidateGroomText(bytes); }, [&] { ParseGroomText(bytes); });
  // The front door (flexkin/any_scenario.h) reads the same text, of any kind, once; a robot tree
  // ("robot") is the arm above read as a tree.
  ScenarioReadOptions options;
  options.robot.urdf_tree_loader = [](const std::string&, const std::string& base_link,
                                      const std::vector<UrdfTool>& tools) {
    return RobotTreeFromUrdf(kUrdf, base_link, tools);
  };
  const AnyScenario any = ReadScenarioText(bytes, options);
  if (any.valid() != (any.chain || any.groom || any.robot || any.tree)) {
    throw std::logic_error("the front door's problems and its scenario disagree");
  }
}

void ReadResult(const std::string& bytes) {
  if (bytes.compare(0, 4, std::string("PK\x03\x04", 4)) != 0) {
    // JSON: a robot trajectory or a tree result (flexkin render tells them by their "format"),
    // or a chain result.
    if (bytes.find("flexkin-robot-trajectory") != std::string::npos) {
      RobotTrajectoryFromText(bytes);
    } else if (bytes.find("flexkin-tree-result") != std::string::npos) {
      ReadTreeResultFile(WriteTemporary(bytes, "tree.json"));
    } else {
      ResultFromText(bytes);
    }
    return;
  }
  const std::string path = WriteTemporary(bytes, "result.npz");
  if (IsTreeResultFile(path)) {
    ReadTreeResultFile(path);
    return;
  }
  if (!IsStrandFile(path)) {
    ReadResultFile(path);
    return;
  }
  StrandFileReader reader(path);
  StrandFrame frame;
  while (reader.Next(&frame)) {
  }
}

void ReadUrdf(const std::string& bytes) { ArmFromUrdf(bytes); }

void ReadGltf(const std::string& bytes) {
  ReadGltfJointPositions(WriteTemporary(bytes, "in.gltf"));
}

const std::vector<Target>& Targets() {
  static const std::vector<Target> targets = {
      {"scenario", ReadScenario}, {"robot", ReadRobotScenario}, {"groom", ReadGroomScenario},
      {"result", ReadResult},     {"urdf", ReadUrdf},           {"gltf", ReadGltf}};
  return targets;
}

int RunOne(void (*read)(const std::string& bytes), const uint8_t* data, size_t size) {
  try {
    read(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const InputError& e) {
    if (std::string(e.what()).empty()) {
      std::fprintf(stderr, "InputError with an empty message\n");
      std::abort();
    }
  } catch (const std::system_error&) {
  }
  return 0;
}

}  // namespace flexkin::fuzz

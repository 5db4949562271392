#pragma once
// The readers of hostile input that the fuzz targets (fuzz/*_fuzzer.cc, docs/fuzzing.md) and the
// regression test (tests/fuzz_regression_test.cc) feed bytes to, one function per target. Each
// reads `bytes` with flexkin's own entry points and returns, or throws what those document:
// flexkin::InputError for content that is not valid, std::system_error for I/O. Anything else
// escaping (another exception, a crash, a sanitizer report) is a finding.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace flexkin::fuzz {

// The chain scenario reader of `flexkin run` (flexkin/scenario.h): ValidateScenarioText, then
// ParseScenarioText; checks that the two agree (no problems if and only if it parses).
void ReadScenario(const std::string& bytes);
// The robot scenario reader of `flexkin robot` (flexkin/robot_scenario.h), the same way. A
// scenario naming a URDF file ("urdf") gets a small built-in URDF arm instead of a file, so that
// the fuzzer reaches the URDF chain options without reading the file system.
void ReadRobotScenario(const std::string& bytes);
// The groom scenario reader (flexkin/groom.h), the same way (a groom that would grow over a
// million points is only validated: the fuzzer's memory limit), then the front door
// (flexkin/any_scenario.h, ReadScenarioText) on the same text.
void ReadGroomScenario(const std::string& bytes);
// Result files (flexkin/result_io.h): an .npz archive (bytes starting "PK\x03\x04") through a
// temporary file: a strand file (IsStrandFile) with the strand file reader
// (flexkin/strand_file.h, every frame read), any other with ReadResultFile; anything else as JSON:
// a robot trajectory (text naming "flexkin-robot-trajectory") with RobotTrajectoryFromText, any
// other with ResultFromText.
void ReadResult(const std::string& bytes);
// URDF text through urdfdom (flexkin/urdf.h): ArmFromUrdf with the default chain.
void ReadUrdf(const std::string& bytes);
// glTF read-back (include/flexkin/gltf.h): ReadGltfJointPositions of the bytes in a temporary file.
void ReadGltf(const std::string& bytes);

struct Target {
  const char* name;  // the fuzzer is <name>_fuzzer, its corpus fuzz/corpus/<name>/
  void (*read)(const std::string& bytes);
};
// Every target, in the order above.
const std::vector<Target>& Targets();

// The body of LLVMFuzzerTestOneInput: runs `read` on the bytes, accepts InputError (with a
// non-empty message; an empty one aborts) and std::system_error, and lets anything else escape.
int RunOne(void (*read)(const std::string& bytes), const uint8_t* data, size_t size);

}  // namespace flexkin::fuzz

// Moves a two-link chain with the installed library and reads a scenario and a robot scenario from
// text; exits 0 only if the lengths are kept and both scenarios read as written. Every installed
// header is included: they need only Eigen (no nlohmann_json, no URDF parser).
#include <flexkin/arm.h>
#include <flexkin/chain.h>
#include <flexkin/curves.h>
#include <flexkin/error.h>
#include <flexkin/leader.h>
#include <flexkin/link_step.h>
#include <flexkin/overall.h>
#include <flexkin/propagate.h>
#include <flexkin/result_io.h>
#include <flexkin/robot_scenario.h>
#include <flexkin/run.h>
#include <flexkin/scenario.h>
#include <flexkin/vocabulary.h>

#include <cstdio>

#if defined(INCLUDE_NLOHMANN_JSON_HPP_) || defined(INCLUDE_NLOHMANN_JSON_FWD_HPP_)
#error "an installed flexkin header includes nlohmann/json; the public headers must be free of it"
#endif

int main() {
  flexkin::Points points(3, 2);
  points << 0.0, 0.0, 0.0, 1.0, 0.0, 2.0;
  flexkin::Chain chain = flexkin::MakeChain(points);
  flexkin::MoveLeader(flexkin::Method::kTractrix, Eigen::Vector2d(3.0, 0.0), 10, &chain);
  const double error = flexkin::MaxRelativeLengthError(chain);
  std::printf("max relative length error %.3g\n", error);

  const flexkin::Scenario scenario = flexkin::ParseScenarioText(
      R"({"curve": {"points": [[0, 0], [1, 0]]}, "leader": {"pull": [1, 0], "steps": 4}})");
  const flexkin::RobotScenario robot = flexkin::ParseRobotScenarioText(
      R"({"arm": {"links": 3, "link_length": 1}, "path": {"type": "line", "to": [2, 1], "steps": 5}})");
  const bool read = scenario.leader_steps.rows() == 4 && robot.model.num_links() == 3 &&
                    robot.path.rows() == 5 &&
                    flexkin::ValidateRobotScenarioText(R"({"arm": {"links": 2}})").size() == 2;
  std::printf("scenarios read: %s\n", read ? "yes" : "no");
  return error < 1e-14 && read ? 0 : 1;
}

// Prints one of the URDFs of snake_urdfs.h: snake_urdf_writer DESIGN [MODULES], DESIGN one of
// pitch_yaw, universal, roll, prismatic, multi_turn (MODULES: the snakes' modules, default 8).
// The examples' robot_pitch_yaw_snake.urdf and robot_universal_snake.urdf are
//   snake_urdf_writer pitch_yaw 8 > examples/robot_pitch_yaw_snake.urdf
//   snake_urdf_writer universal 8 > examples/robot_universal_snake.urdf
// (tests/urdf_snake_test.cc checks that they still are).
#include <cstdio>
#include <cstdlib>
#include <string>

#include "snake_urdfs.h"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr,
                 "usage: snake_urdf_writer pitch_yaw|universal|roll|prismatic|multi_turn "
                 "[MODULES]\n");
    return 2;
  }
  const int modules = argc == 3 ? std::atoi(argv[2]) : 8;
  if (modules < 1) {
    std::fprintf(stderr, "snake_urdf_writer: MODULES must be a positive integer\n");
    return 2;
  }
  for (const flexkin::snakes::SnakeDesign& design : flexkin::snakes::AllSnakeDesigns(modules)) {
    if (design.name == argv[1]) {
      std::fputs(design.urdf.c_str(), stdout);
      return 0;
    }
  }
  std::fprintf(stderr, "snake_urdf_writer: unknown design \"%s\"\n", argv[1]);
  return 2;
}

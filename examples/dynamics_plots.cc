// The physics checks of dynamic chains (docs/dynamics.md) as numbers to plot: writes CSV files
// into the folder given (default "out/dynamics"), which scripts/dynamics_plots.py draws.
//   pendulum_period.csv  the pendulum's period error against the exact period, by amplitude,
//                        projection and sub-steps
//   hanging_modes.csv    a hanging chain's first mode (32, 64, 128 links): the frequency's error
//                        against the discrete chain's own linearized mode, by projection
//   energy.csv           an 8-link rope released from horizontal, no damping: the energy at every
//                        frame over 10 s at 60 Hz, by projection
//   tip_path.csv         the same rope's tip over 0.5 s with 1, 2, 4, 8 and 64 sub-steps
// Usage: dynamics_plots [folder]
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "chain_physics.h"
#include "flexkin/chain.h"
#include "flexkin/dynamics.h"

namespace {

using flexkin::testing_physics::ChainInMode;
using flexkin::testing_physics::DiscreteModes;
using flexkin::testing_physics::EllipticK;
using flexkin::testing_physics::Horizontal;
using flexkin::testing_physics::kG;
using flexkin::testing_physics::Options;
using flexkin::testing_physics::Period;
using flexkin::testing_physics::SwingOmega;

using flexkin::Chain;
using flexkin::DynamicOptions;
using flexkin::DynamicResult;
using flexkin::Points;
using flexkin::Projection;

const Projection kAll[] = {Projection::kOverall, Projection::kShake, Projection::kTractrix,
                           Projection::kDftl};

Points Still(int frames) { return Points::Zero(frames, 2); }

FILE* Open(const std::string& path) {
  FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) {
    std::perror(path.c_str());
    std::exit(1);
  }
  return file;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string folder = argc > 1 ? argv[1] : "out/dynamics";
  std::filesystem::create_directories(folder);

  // The pendulum (one link of length 1, from rest at the amplitude), 20 s.
  FILE* file = Open(folder + "/pendulum_period.csv");
  std::fprintf(file, "amplitude,projection,substeps,period,exact,relative_error\n");
  for (int a = 1; a <= 15; ++a) {
    const double amplitude = 0.1 * a;
    const double exact = 4.0 * std::sqrt(1.0 / kG) * EllipticK(std::sin(0.5 * amplitude));
    Points p(2, 2);
    p << 0.0, 0.0, std::sin(amplitude), -std::cos(amplitude);
    const Chain chain = flexkin::MakeChain(p);
    for (const Projection projection : kAll) {
      for (const int substeps : {1, 8}) {
        const DynamicResult r =
            flexkin::SimulateChain(chain, Still(1200), Options(projection, substeps));
        std::vector<double> x;
        for (const Points& f : r.frames) x.push_back(f(1, 0));
        const double period = Period(x, 1.0 / 60.0);
        std::fprintf(file, "%.2f,%s,%d,%.9f,%.9f,%.6e\n", amplitude,
                     flexkin::ProjectionName(projection), substeps, period, exact,
                     std::fabs(period - exact) / exact);
      }
    }
  }
  std::fclose(file);
  std::printf("%s/pendulum_period.csv\n", folder.c_str());

  // The hanging chain's first mode, 10 s, 4 sub-steps (SHAKE on 128 links: 16).
  file = Open(folder + "/hanging_modes.csv");
  std::fprintf(file, "links,mode,projection,substeps,omega,discrete,relative_error\n");
  for (const int n : {32, 64, 128}) {
    Eigen::MatrixXd modes;
    const Eigen::VectorXd omega = DiscreteModes(n, 1.0, &modes);
    const Chain chain = ChainInMode(n, 1.0, modes, 0);
    for (const Projection projection : kAll) {
      const int substeps = projection == Projection::kShake && n == 128 ? 16 : 4;
      const DynamicResult r =
          flexkin::SimulateChain(chain, Still(600), Options(projection, substeps));
      const double measured = SwingOmega(r, n);
      std::fprintf(file, "%d,1,%s,%d,%.9f,%.9f,%.6e\n", n, flexkin::ProjectionName(projection),
                   substeps, measured, omega[0], std::fabs(measured - omega[0]) / omega[0]);
    }
  }
  std::fclose(file);
  std::printf("%s/hanging_modes.csv\n", folder.c_str());

  // Energy of the 8-link rope from horizontal, no damping, 16 sub-steps, 10 s at 60 Hz.
  file = Open(folder + "/energy.csv");
  std::fprintf(file, "time,overall,shake,tractrix,dftl\n");
  std::vector<Eigen::VectorXd> energy;
  for (const Projection projection : kAll) {
    energy.push_back(
        flexkin::SimulateChain(Horizontal(8), Still(600), Options(projection, 16)).energy);
  }
  for (Eigen::Index f = 0; f < energy[0].size(); ++f) {
    std::fprintf(file, "%.6f,%.9f,%.9f,%.9f,%.9f\n", f / 60.0, energy[0][f], energy[1][f],
                 energy[2][f], energy[3][f]);
  }
  std::fclose(file);
  std::printf("%s/energy.csv\n", folder.c_str());

  // The rope's tip over 0.5 s with 1, 2, 4, 8 and 64 sub-steps.
  file = Open(folder + "/tip_path.csv");
  std::fprintf(file, "projection,substeps,time,x,y\n");
  for (const Projection projection : kAll) {
    for (const int substeps : {1, 2, 4, 8, 64}) {
      const DynamicResult r =
          flexkin::SimulateChain(Horizontal(8), Still(30), Options(projection, substeps));
      for (size_t f = 0; f < r.frames.size(); ++f) {
        std::fprintf(file, "%s,%d,%.6f,%.9f,%.9f\n", flexkin::ProjectionName(projection), substeps,
                     f / 60.0, r.frames[f](8, 0), r.frames[f](8, 1));
      }
    }
  }
  std::fclose(file);
  std::printf("%s/tip_path.csv\n", folder.c_str());
  return 0;
}

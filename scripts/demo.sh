#!/usr/bin/env bash
# make demo: runs the paper's scenarios (examples/*.json) with the flexkin command line, writes
# the results to out/, and prints for each the link-length error, the L2 metric and the
# path-length profile; then the closed-form check of Fig. 7 and the Fig. 6 comparison; then
# renders every result into out/ (figures, plots, MP4 and GIF animations); then the Python
# examples (docs/python-examples.md) into out/python/.
set -euo pipefail
build=${1:-build}
cd "$(dirname "$0")/.."
flexkin="$build/apps/flexkin"
mkdir -p out
for scenario in examples/fig*.json; do
  name=$(basename "$scenario" .json)
  echo "== $name"
  "$flexkin" run "$scenario" -o "out/$name.json" --report full
done
echo "== closed form and comparisons"
"$build/examples/fig07_closed_form" examples/fig07_straight_link.json
"$build/examples/fig06_compare" examples/fig06_parabola_multi_step.json \
  examples/fig06_parabola_single_step.json examples/fig06_parabola_overall_multi_step.json \
  examples/fig06_parabola_overall_single_step.json
echo "== dynamic chains: the physics checks' numbers and plots (docs/dynamics.md)"
"$build/examples/dynamics_plots" out/dynamics
/usr/bin/python3 scripts/dynamics_plots.py out/dynamics
echo "== robot arm with a fixed base (docs/robots.md)"
"$flexkin" robot examples/robot_planar_8link.json -o out/robot_planar_8link.json \
  --csv out/robot_planar_8link_joints.csv
# The spatial snake read from a URDF (revolute joints about given axes). Exit 3 would mean some
# targets not reached (reported, docs/robots.md); it does not stop the demo.
"$flexkin" robot examples/robot_snake_urdf.json -o out/robot_snake_urdf.json \
  --csv out/robot_snake_urdf_joints.csv || [ $? -eq 3 ]
# Any serial robot: an 8-module universal-joint snake read from its URDF (joints grouped in pairs
# at one point), its head pointing down a slope and its joints kept within their velocity limits.
"$flexkin" robot examples/robot_universal_snake.json -o out/robot_universal_snake.json \
  --csv out/robot_universal_snake_joints.csv
# A spatial arm whose bend limits saturate along the path: every target is reachable and reached,
# most through the joint-space step (docs/robots.md, "Joint limits").
"$flexkin" robot examples/robot_spatial_limits.json -o out/robot_spatial_limits.json \
  --csv out/robot_spatial_limits_joints.csv
echo "== tractrix against the Jacobian pseudo-inverse (Orocos KDL), Ravi et al. 2010's arm"
for scenario in robot_ravi_lines robot_ravi_circle; do
  "$build/examples/robot_compare" "examples/$scenario.json" "out/${scenario}_compare"
done
echo "== hair on a head that turns and nods (docs/strands.md, docs/groom-format.md)"
# 5,000 strands of 24 links grown on a sphere of radius 0.1 m, stepped by the strand engine
# frame by frame into a strand file (NumPy .npz), then drawn: a figure of four moments, an MP4
# and the many-strand viewer. The README's frame is the figure with 1,500 of the strands drawn.
"$flexkin" run examples/groom_head.json -o out/groom_head.npz
"$flexkin" render out/groom_head.npz -o out --formats svg,png,mp4,html --quiet
mkdir -p out/groom_head_readme
"$flexkin" render out/groom_head.npz -o out/groom_head_readme --formats png --max-strands 1500 \
  --elevation 10 --quiet
# What the hair did, read back with numpy alone (no flexkin): the motion dying out toward the
# tips, and every link's length.
/usr/bin/python3 examples/python/hair_numpy.py out/groom_head.npz
echo "== hair with inertia and gravity (docs/dynamics.md, \"Strands\"): it falls from its grown"
echo "   shape onto the scalp, swings when the head turns and nods, settles when it stops"
"$flexkin" run examples/groom_head_gravity.json -o out/groom_head_gravity.npz
"$flexkin" render out/groom_head_gravity.npz -o out --formats png,mp4,html --quiet
# The energy and the tips' paths, then the same with the overall projection (about 10 s).
/usr/bin/python3 examples/python/hair_dynamics_plot.py out/groom_head_gravity.npz
"$flexkin" run examples/groom_head_gravity.json -o out/groom_head_gravity_overall.npz \
  --projection overall
/usr/bin/python3 examples/python/hair_dynamics_plot.py out/groom_head_gravity_overall.npz
echo "== colliders (docs/colliders.md): a rope round a post, a thick rope across a floor and round"
echo "   a post, a rope pushed aside by a passing ball (a keyframed collider), a snake threading"
echo "   20 pegs (follow_path and tractrix)"
for name in rope_round_post rope_post_floor rope_swept snake_pegs snake_pegs_tractrix; do
  "$flexkin" run "examples/$name.json" -o "out/$name.json"
  "$flexkin" render "out/$name.json" -o out --formats png,mp4,html --quiet
done
echo "== trees (docs/trees.md): two arms on a spine whose hands go round circles, the base fixed"
echo "   (the passes between the targets), a plant whose trunk sways (its canopy following), and a"
echo "   torso reaching with both hands while its head follows a ball (a pointing goal), and a"
echo "   two-armed URDF robot (15 revolute joints with limits) whose hands go round two circles while"
echo "   its head camera watches the left hand (the joints solved in joint space, docs/trees.md),"
echo "   and the same robot with a lift, a telescoping arm and a rising neck (prismatic joints)"
for name in tree_two_arms tree_plant tree_torso tree_robot_two_arms tree_robot_lift; do
  "$flexkin" run "examples/$name.json" -o "out/$name.npz"
  # The figure, the plots, the animation, the viewer and the glTF (a bone per link) of the tree
  # result.
  "$flexkin" render "out/$name.npz" -o out --formats svg,plots,mp4,gif,html,glb --quiet
done
# The passes and the residual of every frame beside a few frames (matplotlib).
/usr/bin/python3 examples/python/tree_figure.py out/tree_two_arms.npz
/usr/bin/python3 examples/python/tree_figure.py out/tree_plant.npz --view y
echo "== a dynamic chain (docs/dynamics.md): a rope of 40 links released from horizontal, its"
echo "   first point held, falling under gravity (overall projection, 3 s at 60 fps)"
"$flexkin" run examples/rope_fall.json -o out/rope_fall.json
"$flexkin" render out/rope_fall.json -o out --formats png,plots,mp4,html --quiet
echo "== figures, plots, animations, viewers and glTF (docs/rendering.md)"
for result in out/fig*.json; do
  "$flexkin" render "$result" -o out --formats svg,png,pdf,plots,mp4,gif,html,glb --quiet
done
echo "== Python examples (docs/python-examples.md)"
# The same figures' numbers and the robot arm through the Python module, drawn with matplotlib,
# and a sweep of 1,000 variations on dask.distributed checked against the serial results.
python=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' "$build/CMakeCache.txt" 2>/dev/null || true)
python=${python:-/usr/bin/python3}
if [ -d "$build/python/flexkin" ] && ls "$build"/python/flexkin/_flexkin*.so >/dev/null 2>&1; then
  mkdir -p out/python
  for example in fig06_compare fig07_closed_form arm_circle; do
    PYTHONPATH="$build/python" "$python" "examples/python/$example.py" --out out/python
  done
  PYTHONPATH="$build/python" "$python" examples/python/dask_sweep.py
  # A 16-module snake robot (its own URDF) threading 20 pegs, tractrix and follow_path, with its
  # clearance plot and its joints checked against the URDF's limits (docs/colliders.md).
  PYTHONPATH="$build/python" "$python" scripts/snake_robot_demo.py --build "$build" \
    --out out/snake_robot
  # The Blender add-on (docs/blender.md): a tail and a rope baked and rendered by Blender itself.
  if command -v blender > /dev/null; then
    echo "== Blender: a tail carried by an animated Empty and a rope swung by a hand, baked by the"
    echo "   add-on and rendered headless (out/blender_tail.png, out/blender_rope.png)"
    blender -b --factory-startup --python blender/examples/walkthrough.py -- \
      "$build/python" out 2>&1 | grep '^wrote' || { echo "the Blender walkthrough failed" >&2; exit 1; }
  fi
else
  echo "skipped: the Python module is not built ($build/python/flexkin; docs/python.md)"
fi
echo "results: out/*.json (format: docs/result-format.md)"
echo "hair: out/groom_head.npz (docs/strands.md: numpy.load reads it), out/groom_head.{svg,png,mp4,html}"
echo "pictures: out/*.{svg,png,pdf}, out/*_{path_length,link_angles,length_error}.{svg,png},"
echo "  out/*.{mp4,gif}, out/*.html (open in a browser), out/*.glb (docs/rendering.md)"
echo "Python examples' figures: out/python/*.png (docs/python-examples.md)"
echo "trees: out/tree_*.npz (docs/trees.md, \"Results\"), their figures out/tree_*.{svg,png},"
echo "  plots out/tree_*_{path_length,length_error,target_miss,joint_angles}.{svg,png},"
echo "  animations out/tree_*.{mp4,gif}, viewers out/tree_*.html and glTF out/tree_*.glb (docs/trees.md, \"Pictures\")"

"""Benchmark of the tuning methods: over 20 seeds, the median number of distinct evaluations
each needs to come within 0.5 points of the grid optimum, on Cones and Teddy, for the 1-D window
space and the 4-D sad space; random search at the Q-learner's budget; and generalisation
(tune on one scene, score the tuned parameters on the other)."""

from __future__ import annotations

import os
import statistics
import sys
from pathlib import Path

from host.stereo import MatcherParams, load_scene
from host.tuning.learners import tune
from host.tuning.objective import Objective, mean_bad
from host.tuning.spaces import make_space

SEEDS = range(20)
STEPS = {"paper": 20, "qlearning": 1500, "random": 10_000}


def median_reach(results, target: float) -> str:
    reach = [r.evaluations_to_reach(target) for r in results]
    ok = [x for x in reach if x is not None]
    if not ok:
        return f"never (0/{len(reach)})"
    med = statistics.median([x if x is not None else float("inf") for x in reach])
    return f"{med:5.1f} ({len(ok)}/{len(reach)} runs reach it)"


def best_within(result, budget: int) -> float:
    """The best bad % a run had found after `budget` distinct evaluations."""
    return min(bad for _, bad in result.visited[:budget])


def main() -> int:
    data = os.environ.get("STEREO_SERVO_DATA")
    if not data:
        print("STEREO_SERVO_DATA is not set: the tuning benchmark needs Cones and Teddy")
        return 0
    scenes = {n: load_scene(Path(data) / "middlebury" / n) for n in ("cones", "teddy")}
    base = MatcherParams(num_disparities=64, border="clip")
    tuned = {}
    for space_name in ("window", "sad"):
        space = make_space(space_name, base)
        for name, scene in scenes.items():
            obj = Objective.on_scenes([scene], space.params)
            g = tune("grid", obj, space, 0, 0)
            target = g.best_bad + 0.5
            print(f"\n{space_name} space ({space.size} states) on {name}: grid optimum "
                  f"{g.best_bad:.2f}% at {space.values(g.best_state)}; grid pays {space.size}")
            methods = ["paper", "qlearning", "random"] if space_name == "window" else [
                "qlearning", "random"]
            runs = {m: [tune(m, obj, space, min(STEPS[m], space.size) if m == "random"
                             else STEPS[m], s) for s in SEEDS] for m in methods}
            for m, results in runs.items():
                print(f"  {m:<10} evaluations to within 0.5 points: "
                      f"{median_reach(results, target)}")
            q = [r.evaluations_to_reach(target) or space.size for r in runs["qlearning"]]
            budget = int(statistics.median(q))
            rnd = [tune("random", obj, space, budget, s) for s in SEEDS]
            hit_q = sum(r.evaluations_to_reach(target) is not None
                        and r.evaluations_to_reach(target) <= budget for r in runs["qlearning"])
            hit_r = sum(r.evaluations_to_reach(target) is not None for r in rnd)
            print(f"  at the Q-learner's median budget of {budget} evaluations "
                  f"({100 * budget / space.size:.1f}% of the grid): qlearning reaches it in "
                  f"{hit_q}/20 runs, random in {hit_r}/20; median best bad qlearning "
                  f"{statistics.median(best_within(r, budget) for r in runs['qlearning']):.2f}%, "
                  f"random {statistics.median(r.best_bad for r in rnd):.2f}%")
            tuned[(space_name, name)] = space.params(g.best_state)
    print("\ngeneralisation (grid-tuned parameters, bad % nonocc):")
    for space_name in ("window", "sad"):
        for src, dst in (("cones", "teddy"), ("teddy", "cones")):
            p = tuned[(space_name, src)]
            own = mean_bad([scenes[dst]], tuned[(space_name, dst)])
            print(f"  {space_name}: tuned on {src}: {mean_bad([scenes[src]], p):.2f}% there, "
                  f"{mean_bad([scenes[dst]], p):.2f}% on {dst} (tuned on {dst} itself: {own:.2f}%)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

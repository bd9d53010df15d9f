"""A camera knocked while the acquisition is still proving which marker is the robot's: the
re-acquisition after the re-reference starts that proof again (its probe), it does not take
the marker it was looking at for the robot (host/servo/loop.py's _reacquire)."""

from __future__ import annotations

import math

from host.servo.phase import Phase
from host.servo_run import UNSAFE, Rules, run_servo
from host.sim.faults import Event, WorldFaults
from host.sim.run import Setup, simulation
from host.sim.trials import Judge
from host.sim.world import Box

SEED = 3


def test_a_knock_during_the_probe_of_a_look_alike_does_not_make_it_the_robot():
    """The robot at 2.61 m, a second robot-like body with the same marker standing at 1.75 m
    (0.45 m right), which the acquisition measures first; the rig is pitched 1.26 degrees
    down as its probe move begins. The probe cut short had shown nothing: before, the
    re-acquisition kept the estimate of the look-alike and, the controller's heading
    default taken for a probed one, skipped the probe and drove on a marker 0.86 m nearer
    than the robot (unsafe)."""
    boxes = (Box(1.29, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30),
             Box(2.4, 0.60, 0.95, 0.55))
    setup = Setup(start_z_m=2.61, start_x_m=-0.0115, start_theta=-0.0611, boxes=boxes,
                  seed=SEED, faults=WorldFaults(events=(
                      Event(0.0, "decoy", x_m=0.45, z_m=1.746),)))
    with simulation(setup) as sim:
        servo, knocked, probed_after = sim.servo, [], []
        step = servo.step

        def knock_at_probe(truth: float = math.nan):
            row = step(truth)
            if not knocked and row.phase == Phase.PROBE:
                sim.source.renderer.pitch_deg += 1.26
                knocked.append(row.t)
            elif knocked and row.phase == Phase.PROBE and servo.recovery.recovered:
                probed_after.append(row.t)
            return row

        servo.step = knock_at_probe  # type: ignore[method-assign]
        end = run_servo(servo, Rules(settle_s=1.0, limit_s=20.0, lost_s=5.0, hold_from_s=3.0),
                        sim.source.clock, lambda: sim.world.robot.z_m, watch=Judge(sim))
    assert knocked, "the acquisition never probed"
    assert any(n.startswith("re-referenced") for n in servo.notes), servo.notes
    assert end.how != UNSAFE, (end.how, end.reason)
    assert probed_after, servo.notes  # the re-acquisition proved the marker again

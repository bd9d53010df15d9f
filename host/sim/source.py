"""The simulated camera: renders the world and moves its robot with the board's motor outputs,
both in one deterministic simulated clock (lockstep: processing takes no simulated time)."""

from __future__ import annotations

import ctypes
import math
from collections import deque

import numpy as np

from host.camera.source import StereoFrame, StereoSource
from host.emulator import fast_ms
from host.emulator.board import Board
from host.emulator.emulator import Emulator, Lockstep
from host.sim.faults import Event
from host.sim.rectify import Changed
from host.sim.renderer import Flicker, Renderer
from host.sim.world import Box, Motors, Person, Robot, World


def _first_ms(t_s: float) -> int:
    """The first whole millisecond n whose time n / 1000 (as SimSource.t computes it) is at
    or after t_s."""
    n = math.ceil(t_s * 1000)
    while (n - 1) / 1000 >= t_s:
        n -= 1
    while n / 1000 < t_s:
        n += 1
    return n


_NONE = 1 << 20  # no motor outputs queued yet (outside int16)
_FAR = 1 << 62  # no scene event to come


class _Compiled:
    """The compiled millisecond's state (host.emulator.fast_ms.State) for one native core and
    one world generator: the core's functions and the generator's draw bound once."""

    def __init__(self, lib: ctypes.CDLL, parts: Lockstep, w: World) -> None:
        self.parts, self.rng = parts, w.rng
        self.s = s = fast_ms.State()
        self.ref = ctypes.byref(s)
        self.reason = ctypes.c_int32()
        self.reason_ref = ctypes.byref(self.reason)
        self.run = lib.run_ms
        self.txbuf = ctypes.create_string_buffer(len(parts.core._buf))  # as the core's own
        core_lib = parts.core._lib
        self._draws = w.rng.bit_generator.ctypes  # kept alive with the pointers taken from it

        def addr(fn: object) -> int | None:
            return ctypes.cast(fn, ctypes.c_void_p).value  # type: ignore[arg-type]

        s.guard, s.tick = addr(core_lib.robot_guard), addr(core_lib.robot_tick)
        s.take, s.motors = addr(core_lib.emu_take_tx), addr(core_lib.emu_motors)
        s.rx = addr(core_lib.robot_rx_byte)
        s.draw, s.draw_state = addr(self._draws.next_double), self._draws.state_address
        s.txbuf, s.txcap = ctypes.addressof(self.txbuf), len(self.txbuf)
        m = w.motors
        s.dt, s.wheelbase = 0.001, m.wheelbase_m
        s.v_max, s.dead_zone, s.span = m.v_max_mps, m.dead_zone, 1000 - m.dead_zone

    def load_world(self, w: World) -> None:
        s, r = self.s, w.robot
        s.t, s.travelled = w.t, w.travelled_m
        s.v_left, s.v_right, s.theta, s.x, s.z = r.v_left, r.v_right, r.theta, r.x_m, r.z_m
        s.traction[0], s.traction[1] = w.traction

    def save_world(self, w: World) -> None:
        s, r = self.s, w.robot
        w.t, w.travelled_m = s.t, s.travelled
        r.v_left, r.v_right, r.theta, r.x_m, r.z_m = s.v_left, s.v_right, s.theta, s.x, s.z

    def load_inbound(self, inbound: deque[tuple[float, int]]) -> None:
        s = self.s
        for i, (due, b) in enumerate(inbound):
            s.in_due[i], s.in_byte[i] = due, b
        s.in_len, s.in_used = len(inbound), 0

    def take_inbound(self, inbound: deque[tuple[float, int]]) -> None:
        """The bytes the core was handed off the line's queue."""
        s = self.s
        if s.in_used:
            for _ in range(s.in_used):
                inbound.popleft()
            self.load_inbound(inbound)


class SimSource(StereoSource):
    """Frames at fps; between frames the world and the board advance in 1 ms steps, the robot
    driven by the duties the firmware applies, latency_ms later. The first reference_frames
    frames show the scene without the robot (the reference phase). The right view is captured
    skew_ms after the left; a dropped frame never arrives (the next one comes a period later).
    Captures keep the camera's own schedule: time the host spends waiting on the link (which
    runs the same clock, host.emulator.lockstep) does not shift it, and a capture the host was
    too busy to take is overwritten by the next. The scene's events (host.sim.faults.Event)
    happen at their times; what each did is in log."""

    def __init__(self, world: World, board: Board, fps: float = 30.0,
                 reference_frames: int = 5, renderer: Renderer | None = None,
                 events: tuple[Event, ...] = (), latency_ms: float = 0.0, seed: int = 0) -> None:
        self.world, self.board, self.fps = world, board, fps
        self.renderer = renderer or Renderer(world, seed=world.seed)
        self.reference_frames = reference_frames
        self.events = sorted(events, key=lambda e: e.t_s)
        self.latency_ms = latency_ms
        self.rng = np.random.default_rng(seed + 104729)
        self.index = 0
        self.now_ms = 0
        self.dropped = 0
        self._due_ms = 0  # the left capture of the frame being read
        self._pending: deque[tuple[int, tuple[int, int]]] = deque()
        self._applied = (0, 0)
        self._queued: tuple[int, int] | None = None  # the motor outputs queued last
        self._occluded_until = -1.0
        self._until: dict[str, float] = {}  # when each lasting event ends
        self._lane_box: Box | None = None
        self._walker: Event | None = None
        self._freeze: Event | None = None
        self._held: list[tuple[np.ndarray, float] | None] = [None, None]  # last image, stamp
        self._made: list[tuple[np.ndarray, Changed | None] | None] = [None, None]
        self.log: list[str] = []  # what happened in the scene, with times
        self._parts: Lockstep | None = None  # the native board's millisecond (_native)
        self._fast: _Compiled | None = None  # its compiled form (_run_ms_compiled)

    @property
    def t(self) -> float:
        return self.now_ms / 1000

    def clock(self) -> float:
        return self.t

    @property
    def frozen(self) -> bool:
        """A sensor is repeating its last image now (the truth a test judges the servo by)."""
        return self._freeze is not None

    def run_ms(self, ms: int) -> None:
        """Advance the world and the board by ms, one millisecond at a time. The scene's events
        are looked at in the milliseconds where one is due (_wake_ms), and the motor outputs
        are queued for their latency only when they change: the same steps as looking every
        millisecond and queueing every output."""
        parts = self._native()
        if parts is not None:
            with parts.emu.lock:
                self._run_ms_native(ms, parts, until_tx=False)
            return
        self._pending_back()
        board, step, pending = self.board, self.world.step, self._pending
        latency = int(round(self.latency_ms))
        wake = self._wake_ms()
        for _ in range(ms):
            now = self.now_ms
            if now >= wake:
                self._apply_events()
                wake = self._wake_ms()
            motors = board.motors()
            if motors != self._queued:
                pending.append((now + latency, motors))
                self._queued = motors
            while pending and pending[0][0] <= now:
                self._applied = pending.popleft()[1]
            step(0.001, *self._applied)
            board.advance(1)
            self.now_ms = now + 1

    def run_until_tx(self, ms: int) -> None:
        """run_ms(1) up to ms times, stopping after the millisecond by which the board has a
        byte for the host (host.emulator.lockstep's wait for a reply)."""
        parts = self._native()
        if parts is not None:
            with parts.emu.lock:
                self._run_ms_native(ms, parts, until_tx=True)
            return
        board = self.board
        if not isinstance(board, Emulator):
            raise TypeError("run_until_tx needs the native core's board (an Emulator)")
        for _ in range(ms):
            self.run_ms(1)
            if board.has_tx():
                return

    def _native(self) -> Lockstep | None:
        """The native core's millisecond taken apart (Emulator.lockstep) when the world and
        the board are the plain ones, else None; kept while the board's core is the same."""
        board = self.board
        if type(board) is not Emulator or type(self.world) is not World:
            return None
        parts = self._parts
        if parts is None or not parts.current():
            parts = self._parts = board.lockstep()
        return parts

    def _run_ms_native(self, ms: int, parts: Lockstep, until_tx: bool) -> None:
        """run_ms with the native core's board: compiled (host.emulator.fast_ms) where it
        builds, else _run_ms_loop; the same steps either way."""
        if ms <= 0:
            return
        fast = self._compiled(parts)
        if fast is not None and len(parts.emu._inbound) <= fast_ms.INBOUND:
            self._run_ms_compiled(ms, fast, until_tx)
        else:
            self._pending_back()
            self._run_ms_loop(ms, parts, until_tx)

    def _compiled(self, parts: Lockstep) -> _Compiled | None:
        """The compiled millisecond's state for these parts (made again for a new core or a
        new generator), or None where it does not build or the motors are not the plain
        model."""
        fast = self._fast
        w = self.world
        if fast is not None and fast.parts is parts and fast.rng is w.rng:
            return fast
        lib = fast_ms.library()
        if lib is None or type(w.motors) is not Motors:
            return None
        if fast is not None:
            self._pending_back()
        self._fast = fast = _Compiled(lib, parts, w)
        return fast

    def _pending_back(self) -> None:
        """The compiled loop's queue of motor outputs back into _pending (for the loops in
        Python)."""
        fast = self._fast
        if fast is None or not fast.s.pend_len:
            return
        s = fast.s
        for _ in range(s.pend_len):
            i = s.pend_head
            self._pending.append((s.pend_due[i], (s.pend_m[i][0], s.pend_m[i][1])))
            s.pend_head = (i + 1) % fast_ms.PENDING
            s.pend_len -= 1

    def _run_ms_compiled(self, ms: int, fast: _Compiled, until_tx: bool) -> None:
        """_run_ms_loop's milliseconds in C (host.emulator.fast_ms.run_ms) between the scene's
        events and the board's bytes for the host, which are handled here as there."""
        s, w, emu = fast.s, self.world, fast.parts.emu
        f = w.motor_faults
        inbound, outbound = emu._inbound, emu._outbound
        pending = self._pending
        while pending:  # from a loop in Python before
            due, (left, right) = pending.popleft()
            i = (s.pend_head + s.pend_len) % fast_ms.PENDING
            s.pend_due[i], s.pend_m[i][0], s.pend_m[i][1] = due, left, right
            s.pend_len += 1
        s.a = 1.0 - math.exp(-0.001 / w.motors.tau_s)
        s.sag, s.push, s.slip = f.sag_per_m, f.push_mps, f.slip
        s.gain[0], s.gain[1] = f.gain
        s.offset[0], s.offset[1] = f.offset
        s.latency = int(round(self.latency_ms))
        s.applied[0], s.applied[1] = self._applied
        queued = self._queued
        s.queued[0], s.queued[1] = queued if queued is not None else (_NONE, _NONE)
        s.emu_now, s.ticked = emu.now_ms, emu._ticked_ms
        s.until_tx = until_tx
        fast.load_world(w)
        fast.load_inbound(inbound)
        s.outbound_due = outbound[0][0] if outbound else math.inf
        now, end = self.now_ms, self.now_ms + ms
        wake = self._wake_ms()
        reason, run = fast.reason, fast.run
        try:
            while now < end:
                if now >= wake:
                    self.now_ms = now
                    fast.save_world(w)
                    self._apply_events()
                    wake = self._wake_ms()
                    fast.load_world(w)
                now += run(fast.ref, now, end, _FAR if wake == math.inf else int(wake),
                           fast.reason_ref)
                why = reason.value
                if why == fast_ms.TX:
                    emu.now_ms, emu._ticked_ms = s.emu_now, s.ticked
                    fast.take_inbound(inbound)
                    emu._queue_tx(fast.txbuf.raw[:s.k])
                    if until_tx and outbound and outbound[0][0] <= emu.now_ms:
                        break
                    s.outbound_due = outbound[0][0] if outbound else math.inf
                elif why != fast_ms.BEFORE:
                    break
        finally:
            self.now_ms = now
            fast.save_world(w)
            emu.now_ms, emu._ticked_ms = s.emu_now, s.ticked
            fast.take_inbound(inbound)
            self._applied = (s.applied[0], s.applied[1])
            self._queued = None if s.queued[0] == _NONE else (s.queued[0], s.queued[1])

    def _run_ms_loop(self, ms: int, parts: Lockstep, until_tx: bool) -> None:
        """run_ms with the native core's board: the same steps, in one loop (the world's step
        and the board's advance(1) written out here; World.step and Emulator.advance say what
        each does)."""
        pending, w = self._pending, self.world
        r, m, f = w.robot, w.motors, w.motor_faults
        latency = int(round(self.latency_ms))
        wake = self._wake_ms()
        dt = 0.001
        a = 1.0 - math.exp(-dt / m.tau_s)
        wheel, wheelbase, push = w._wheel, m.wheelbase_m, f.push_mps
        gain, offset = f.gain, f.offset
        read_motors, advance_1 = parts.motors, parts.advance_1
        emu = parts.emu
        outbound = emu._outbound
        applied, queued = self._applied, self._queued
        start = self.now_ms
        sag, sin, cos = f.sag_per_m, math.sin, math.cos
        # the robot's state and the world's clock in locals between the scene's events (which
        # read and move them: written back before, read again after), the same arithmetic
        t, travelled, traction = w.t, w.travelled_m, w.traction
        v_left, v_right, theta, x_m, z_m = r.v_left, r.v_right, r.theta, r.x_m, r.z_m
        try:
            for now in range(start, start + ms):
                if now >= wake:
                    self.now_ms = now
                    w.t, w.travelled_m = t, travelled
                    r.v_left, r.v_right, r.theta, r.x_m, r.z_m = v_left, v_right, theta, x_m, z_m
                    self._apply_events()
                    wake = self._wake_ms()
                    t, travelled, traction = w.t, w.travelled_m, w.traction
                    v_left, v_right, theta, x_m, z_m = r.v_left, r.v_right, r.theta, r.x_m, r.z_m
                motors = read_motors()
                if motors != queued:
                    pending.append((now + latency, motors))
                    queued = motors
                while pending and pending[0][0] <= now:
                    applied = pending.popleft()[1]
                # World.step(dt, *applied)
                t += dt
                supply = max(0.5, 1.0 - sag * travelled)
                duty_left, duty_right = applied
                t_left = (wheel(duty_left, supply, gain[0], offset[0], traction[0])
                          if duty_left else 0.0 * gain[0] * traction[0])
                t_right = (wheel(duty_right, supply, gain[1], offset[1], traction[1])
                           if duty_right else 0.0 * gain[1] * traction[1])
                v_left += (t_left - v_left) * a
                v_right += (t_right - v_right) * a
                v = (v_left + v_right) / 2
                theta += (v_left - v_right) / wheelbase * dt
                x_m += (v * sin(theta) + push) * dt
                z_m += v * cos(theta) * dt
                travelled += abs(v) * dt
                advance_1()
                if until_tx and outbound and outbound[0][0] <= emu.now_ms:
                    ms = now + 1 - start
                    break
        finally:
            w.t, w.travelled_m = t, travelled
            r.v_left, r.v_right, r.theta, r.x_m, r.z_m = v_left, v_right, theta, x_m, z_m
        self.now_ms = start + ms
        self._applied, self._queued = applied, queued

    def _wake_ms(self) -> float:
        """The first millisecond at which _apply_events has something to do: an event due, a
        lasting one or the post's occlusion ending, every millisecond while a person walks."""
        if self._walker is not None:
            return self.now_ms
        times = [*self._until.values()]
        if self.events:
            times.append(self.events[0].t_s)
        if self.world.robot.occlusion:
            times.append(self._occluded_until)
        return min(map(_first_ms, times), default=math.inf)

    def _apply_events(self) -> None:
        w, r = self.world, self.world.robot
        if r.occlusion and self.t >= self._occluded_until:
            r.occlusion = 0.0
        self._end_lasting()
        if self._walker is not None:
            e = self._walker
            w.people = (Person(e.x_m + e.speed_mps * (self.t - e.t_s), e.z_m),)
        while self.events and self.events[0].t_s <= self.t:
            e = self.events.pop(0)
            boxes = list(w.boxes)
            note = ""
            if e.kind == "move" and e.index < len(boxes):
                b = boxes[e.index]
                boxes[e.index] = Box(e.z_m, b.x0_m, b.x1_m, b.height_m)
            elif e.kind == "appear" and e.box is not None:
                boxes.append(Box(*e.box))
            elif e.kind == "vanish" and e.index < len(boxes):
                boxes.pop(e.index)
            elif e.kind == "occlude":
                r.occlusion, self._occluded_until = e.fraction, e.t_s + e.duration_s
            elif e.kind == "facing":
                r.theta = math.radians(e.angle_deg)
            elif e.kind == "lane-box":
                box = self._lane_box_for(e)
                if box is None:
                    note = " (skipped: no room ahead)"
                else:
                    boxes.append(box)
                    note = f" at {box.z_m:.2f} m"
                    if e.duration_s:
                        self._lane_box = box
                        self._until["lane-box"] = self.t + e.duration_s
            elif e.kind == "knock":
                self.renderer.pitch_deg += e.angle_deg
            elif e.kind == "freeze":
                self._freeze, self._until["freeze"] = e, self.t + e.duration_s
            elif e.kind == "flicker":
                self.renderer.flicker = Flicker(e.fraction, e.hz, e.gap_ms / 1000)
                if e.duration_s:
                    self._until["flicker"] = self.t + e.duration_s
            elif e.kind == "behind" and e.index < len(boxes):
                note = self._place_behind(boxes[e.index], e)
            elif e.kind == "walker":
                self._walker, self._until["walker"] = e, self.t + e.duration_s
                w.people = (Person(e.x_m, e.z_m),)
            elif e.kind == "slip":
                w.traction, self._until["slip"] = e.traction, self.t + e.duration_s
            elif e.kind == "drop-burst":
                self._until["drop-burst"] = self.t + e.duration_s
            elif e.kind == "decoy":
                w.decoys = (*w.decoys, Robot(x_m=e.x_m, z_m=e.z_m))
            w.boxes = tuple(boxes)
            self.log.append(f"{self.t:.3f} s {e.describe()}{note}")

    def _end_lasting(self) -> None:
        """End the lasting events whose time is up."""
        w = self.world
        for kind, until in list(self._until.items()):
            if self.t < until:
                continue
            del self._until[kind]
            if kind == "lane-box" and self._lane_box in w.boxes:
                boxes = list(w.boxes)
                boxes.remove(self._lane_box)
                w.boxes, self._lane_box = tuple(boxes), None
            elif kind == "freeze":
                self._freeze = None
            elif kind == "flicker":
                self.renderer.flicker = None
            elif kind == "walker":
                self._walker, w.people = None, ()
            elif kind == "slip":
                w.traction = (1.0, 1.0)
            self.log.append(f"{self.t:.3f} s {kind} ends")

    def _lane_box_for(self, e: Event) -> Box | None:
        """The box ahead_m ahead of the robot's centre, the way it moves (or faces), centred
        on its line; None when that is nearer the camera than 0.35 m or beyond the wall."""
        r, w = self.world.robot, self.world
        vz = (r.v_left + r.v_right) / 2 * math.cos(r.theta)
        way = math.copysign(1.0, vz if abs(vz) > 0.02 else math.cos(r.theta))
        z = r.z_m + way * e.ahead_m
        if not 0.35 <= z <= w.wall_z_m - 0.1:
            return None
        return Box(z, r.x_m - e.width_m / 2, r.x_m + e.width_m / 2, 0.3)

    def _place_behind(self, box: Box, e: Event) -> str:
        """Put the robot behind box so that its edge nearer the view's centre hides `fraction`
        of the card's ring (the left part for a box on the left)."""
        r, g = self.world.robot, self.world.geometry
        r.z_m = max(r.z_m, e.z_m)
        ring = r.marker_radius_m * r.ring_ratio  # m, at the card
        left_box = abs(box.x1_m) < abs(box.x0_m)
        edge = box.x1_m if left_box else box.x0_m
        at = edge * r.z_m / box.z_m  # the edge's line of sight at the robot's depth
        r.x_m = at + ring * (1 - 2 * e.fraction) * (1 if left_box else -1)
        u = g.cx + g.focal_px * r.x_m / r.z_m
        return f" at {r.z_m:.2f} m, x {r.x_m:+.3f} m (column {u:.1f})"

    def _read(self) -> StereoFrame | None:
        period = int(round(1000 / self.fps))
        cam = self.renderer.camera
        skew = int(round(cam.skew_ms))
        if self.index:
            self._due_ms += period
            while self._due_ms < self.now_ms:
                self._due_ms += period
            self.run_ms(self._due_ms - self.now_ms)
            while ((cam.drop and self.rng.random() < cam.drop)
                   or "drop-burst" in self._until):
                self.dropped += 1
                self._due_ms += period
                self.run_ms(period)
        else:
            self._due_ms = self.now_ms
        with_robot = self.index >= self.reference_frames
        t_left = self.t
        left = self._capture(0, with_robot, t_left, t_left)
        self.run_ms(skew)
        right = self._capture(1, with_robot, self.t, t_left)
        self.index += 1
        return StereoFrame(left[0], right[0], left[1], right[1])

    def _capture(self, side: int, with_robot: bool, stamp: float, began: float
                 ) -> tuple[np.ndarray, float]:
        """One sensor's image and its timestamp; a frozen sensor repeats its last image (and,
        with stamps frozen too, its last stamp)."""
        e, held = self._freeze, self._held[side]
        if e is not None and e.sensor == side and held is not None:
            return held[0], stamp if e.stamps else held[1]
        vel = self.renderer.image_velocity()
        blur = (vel[0] * self.renderer.camera.exposure_ms / 1000,
                vel[1] * self.renderer.camera.exposure_ms / 1000)
        image = self.renderer.image(side, with_robot, blur, t_s=began)
        self._held[side] = (image, stamp)
        self._made[side] = (image, self.renderer.changed)
        return image, stamp

    def made(self, side: int) -> tuple[np.ndarray, Changed | None] | None:
        """The side's last rendered image and how the renderer made it (Renderer.changed:
        host.sim.rectify rectifies it again only where it differs from the bare scene)."""
        return self._made[side]

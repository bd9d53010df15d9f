"""The ATmega328P's motor pins derived from its registers, as recorded by the simavr harness:
Timer1's PWM waveform on OC1A (PB1, ENA) and OC1B (PB2, ENB) from WGM, COM, CS, ICR1, OCR1x and
DDRB, and the bridge's direction inputs from PORTD and DDRD. simavr 1.6 does not report the PWM
toggles on PB1/PB2 (shared simavr notes), so the waveform at the pin is computed here from the
datasheet's rules, including the double buffering of OCR1x (a new value takes effect at TOP in
the phase-correct modes, at BOTTOM in the fast and phase-and-frequency-correct ones)."""

from __future__ import annotations

from dataclasses import dataclass

F_CPU = 16_000_000  # the firmware Makefile's F_CPU (tests/firmware/test_build_config.py)
PRESCALER = {0: 0, 1: 1, 2: 8, 3: 64, 4: 256, 5: 1024}  # CS12..CS10; 6, 7: external clock
EN_BITS = {"left": 1, "right": 2}                        # PB1 = OC1A = ENA, PB2 = OC1B = ENB
DIR_BITS = {"left": (4, 5), "right": (6, 7)}             # PD4/PD5 = IN1/IN2, PD6/PD7 = IN3/IN4


@dataclass(frozen=True)
class Io:
    """The watched registers after a change, at a CPU cycle."""

    cycle: int
    portb: int
    ddrb: int
    portd: int
    ddrd: int
    tccr1a: int
    tccr1b: int
    icr1: int
    ocr1a: int
    ocr1b: int
    mcusr: int
    wdtcsr: int

    @property
    def wgm(self) -> int:
        return (self.tccr1b >> 3 & 3) << 2 | self.tccr1a & 3

    @property
    def prescaler(self) -> int:
        return PRESCALER.get(self.tccr1b & 7, 0)


@dataclass(frozen=True)
class Pin:
    """An output pin: a steady level (duty 0 or 1, freq_hz 0), a PWM wave, or not driven
    (an input: driven False)."""

    driven: bool
    duty: float = 0.0
    freq_hz: float = 0.0


def timer1_top(io: Io) -> tuple[int, str] | None:
    """(TOP, kind) of Timer1's PWM mode: kind 'phase' (dual slope) or 'fast'; None when the mode
    is not a PWM mode."""
    m = io.wgm
    fixed = {1: 0xFF, 2: 0x1FF, 3: 0x3FF, 5: 0xFF, 6: 0x1FF, 7: 0x3FF}
    if m in (1, 2, 3):
        return fixed[m], "phase"
    if m in (5, 6, 7):
        return fixed[m], "fast"
    if m in (8, 10):
        return io.icr1, "phase"
    if m == 14:
        return io.icr1, "fast"
    return None


def pwm_frequency(io: Io) -> float:
    """Timer1's PWM frequency in Hz (0 when stopped or not in a PWM mode)."""
    mode, n = timer1_top(io), io.prescaler
    if mode is None or not n or not mode[0]:
        return 0.0
    top, kind = mode
    return F_CPU / (2 * n * top) if kind == "phase" else F_CPU / (n * (top + 1))


def enable_pin(io: Io, motor: str, ocr: int | None = None) -> Pin:
    """The level or waveform on a motor's enable pin; ocr: the compare value in effect (the
    double-buffered one), default the register's."""
    bit = EN_BITS[motor]
    if not io.ddrb >> bit & 1:
        return Pin(False)
    com = io.tccr1a >> (6 if motor == "left" else 4) & 3
    ocr = (io.ocr1a if motor == "left" else io.ocr1b) if ocr is None else ocr
    mode, freq = timer1_top(io), pwm_frequency(io)
    if com < 2 or mode is None or not freq:  # disconnected from the timer: the port bit
        return Pin(True, float(io.portb >> bit & 1))
    top, kind = mode
    duty = min(ocr, top) / top if kind == "phase" else min(ocr + 1, top + 1) / (top + 1)
    if com == 3:
        duty = 1 - duty
    return Pin(True, duty, freq if 0 < duty < 1 else 0.0)


def direction(io: Io, motor: str) -> str:
    """The bridge inputs of a motor: 'forward', 'reverse', 'off' (both low), 'brake' (both high)
    or 'floating' (a pin not an output)."""
    a, b = DIR_BITS[motor]
    if not (io.ddrd >> a & 1 and io.ddrd >> b & 1):
        return "floating"
    return {(0, 0): "off", (1, 0): "forward", (0, 1): "reverse",
            (1, 1): "brake"}[(io.portd >> a & 1, io.portd >> b & 1)]


@dataclass(frozen=True)
class Drive:
    """What a motor's bridge gets from a cycle on: enable pin and direction inputs."""

    cycle: int
    enable: Pin
    direction: str

    @property
    def driving(self) -> bool:
        """The bridge gets power: its enable pin is an output with a duty above 0."""
        return self.enable.driven and self.enable.duty > 0


def timeline(ios: list[Io], motor: str) -> list[Drive]:
    """A motor's pins over time, with the compare value taking effect at the timer's update
    point (TOP or BOTTOM) after each write, counted from when the timer was started."""
    out: list[Drive] = []
    start = None  # cycle at which Timer1 started counting from 0
    effective = 0
    pending: list[tuple[int, int]] = []  # (cycle it takes effect, value), in order
    prev: Io | None = None
    for io in ios:
        while pending and pending[0][0] <= io.cycle:  # updates before this register change
            when, effective = pending.pop(0)
            assert prev is not None
            out.append(Drive(when, enable_pin(prev, motor, effective), direction(prev, motor)))
        if start is None and io.prescaler:
            start = io.cycle
        value = io.ocr1a if motor == "left" else io.ocr1b
        mode = timer1_top(io)
        if mode is None or not io.prescaler or start is None:
            effective, pending = value, []
        elif value != (pending[-1][1] if pending else effective):
            top, kind = mode
            period = io.prescaler * (2 * top if kind == "phase" else top + 1)
            first = start + (io.prescaler * top if kind == "phase" else period)
            k = max(0, -(-(io.cycle - first) // period))
            pending.append((first + k * period, value))
        out.append(Drive(io.cycle, enable_pin(io, motor, effective), direction(io, motor)))
        prev = io
    for when, value in pending:
        assert prev is not None
        out.append(Drive(when, enable_pin(prev, motor, value), direction(prev, motor)))
    return _merge(out)


def _merge(drives: list[Drive]) -> list[Drive]:
    """Sorted by cycle, each state once: a record only where something at the pins changed."""
    out: list[Drive] = []
    for d in sorted(drives, key=lambda d: d.cycle):
        if out and out[-1].cycle == d.cycle:
            out[-1] = d
        elif not out or (out[-1].enable, out[-1].direction) != (d.enable, d.direction):
            out.append(d)
    return out

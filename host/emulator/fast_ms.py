"""The simulation's quiet milliseconds compiled (issue 25): the world's step and the native
core's advance(1), run in C for the milliseconds in which nothing needs Python (no scene event
due, no byte from the board to put on the line). host.sim.source.SimSource._run_ms_native keeps
the loop in Python as the reference and hands it here while this builds (gcc, as the core
does); the same operations in the same order, in IEEE double without contraction and with libm's
own sin, cos (so the same bits as CPython's float and math), the slip drawn from the world's
numpy generator through its bit generator's own next_double, and the core's functions called
through their pointers, in the order Emulator.advance calls them."""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
from pathlib import Path

from host.emulator.build import CACHE, BuildFailed

PENDING = 4096  # the motor outputs waiting out their latency (at most one a millisecond)
INBOUND = 1024  # the host's bytes on their way to the core, as handed in per call

# stop reasons (what the Python loop does next)
BEFORE = 0   # stopped before the millisecond `now`: a scene event is due in it
TX = 1       # the millisecond done, the core had k bytes for the host (in txbuf)
ARRIVED = 2  # the millisecond done, a byte on the line has reached the host (until_tx)
END = 3      # all the milliseconds asked for done

_DEFINES = "".join(f"#define {k} {v}\n" for k, v in (
    ("PENDING", PENDING), ("INBOUND", INBOUND), ("STOP_BEFORE", BEFORE), ("STOP_TX", TX),
    ("STOP_ARRIVED", ARRIVED), ("STOP_END", END)))
SOURCE = _DEFINES + r"""
#include <math.h>
#include <stdint.h>

typedef void (*u32_fn)(uint32_t);
typedef void (*rx_fn)(uint8_t, uint32_t);
typedef uint16_t (*take_fn)(uint8_t *, uint16_t);
typedef uint32_t (*motors_fn)(int16_t *, int16_t *);
typedef double (*draw_fn)(void *);

struct ms {
    /* the world: robot state and clock (in and out) */
    double t, travelled, v_left, v_right, theta, x, z;
    /* its constants and the floor's traction */
    double dt, a, sag, push, wheelbase, gain[2], offset[2], traction[2], slip;
    double v_max, dead_zone, span;
    /* the emulator's clock (in and out) and the core's last tick */
    double emu_now;
    int64_t ticked;
    /* motor outputs: applied, queued last, and the queue waiting out the latency */
    int64_t latency;
    int32_t applied[2], queued[2];
    int64_t pend_due[PENDING];
    int32_t pend_m[PENDING][2];
    int32_t pend_head, pend_len;
    /* the host's bytes on the line to the core: due time and byte; in_used taken so far */
    int32_t in_len, in_used;
    double in_due[INBOUND];
    uint8_t in_byte[INBOUND];
    /* until_tx: when the first byte on the line to the host arrives (INFINITY: none) */
    double outbound_due;
    int32_t until_tx;
    /* the core's functions, the world's generator */
    void *guard, *tick, *take, *motors, *rx, *draw, *draw_state;
    uint8_t *txbuf;
    int32_t txcap, k;
};

static double speed(const struct ms *s, double duty)
{
    if (fabs(duty) <= s->dead_zone)
        return 0.0;
    return copysign(s->v_max * (fabs(duty) - s->dead_zone) / s->span, duty);
}

static double wheel(struct ms *s, int32_t duty, double supply, double gain, double offset,
                    double grip)
{
    double d = (double)duty;
    double v = speed(s, d * supply - copysign(offset, d)) * gain * grip;
    if (s->slip != 0.0 && v != 0.0)
        v *= 1.0 - s->slip * ((draw_fn)s->draw)(s->draw_state);
    return v;
}

/* Milliseconds now .. end-1 (wake: the first in which a scene event is due, looked at unless
 * it is `now`, whose events were just applied); returns the milliseconds done, *reason why it
 * stopped. */
int64_t run_ms(struct ms *s, int64_t now, int64_t end, int64_t wake, int32_t *reason)
{
    int64_t start = now;
    int16_t l, r;
    s->k = 0;
    for (; now < end; now++) {
        if (now >= wake && now != start) {
            *reason = STOP_BEFORE;
            return now - start;
        }
        ((motors_fn)s->motors)(&l, &r);
        if (l != s->queued[0] || r != s->queued[1]) {
            int32_t i = (s->pend_head + s->pend_len) % PENDING;
            s->pend_due[i] = now + s->latency;
            s->pend_m[i][0] = l;
            s->pend_m[i][1] = r;
            s->pend_len++;
            s->queued[0] = l;
            s->queued[1] = r;
        }
        while (s->pend_len && s->pend_due[s->pend_head] <= now) {
            s->applied[0] = s->pend_m[s->pend_head][0];
            s->applied[1] = s->pend_m[s->pend_head][1];
            s->pend_head = (s->pend_head + 1) % PENDING;
            s->pend_len--;
        }
        /* World.step(dt, *applied) */
        double dt = s->dt;
        s->t += dt;
        double supply = 1.0 - s->sag * s->travelled;
        if (!(supply > 0.5))
            supply = 0.5;
        double t_left = s->applied[0]
            ? wheel(s, s->applied[0], supply, s->gain[0], s->offset[0], s->traction[0])
            : 0.0 * s->gain[0] * s->traction[0];
        double t_right = s->applied[1]
            ? wheel(s, s->applied[1], supply, s->gain[1], s->offset[1], s->traction[1])
            : 0.0 * s->gain[1] * s->traction[1];
        s->v_left += (t_left - s->v_left) * s->a;
        s->v_right += (t_right - s->v_right) * s->a;
        double v = (s->v_left + s->v_right) / 2;
        s->theta += (s->v_left - s->v_right) / s->wheelbase * dt;
        s->x += (v * sin(s->theta) + s->push) * dt;
        s->z += v * cos(s->theta) * dt;
        s->travelled += fabs(v) * dt;
        /* Emulator.advance(1) */
        double t = s->emu_now + 1.0;
        s->emu_now = t;
        while (s->in_used < s->in_len && s->in_due[s->in_used] <= t) {
            ((rx_fn)s->rx)(s->in_byte[s->in_used], (uint32_t)(int64_t)t);
            s->in_used++;
        }
        int64_t n = (int64_t)t;
        if (n != s->ticked) {
            s->ticked = n;
            ((u32_fn)s->guard)((uint32_t)n);
            ((u32_fn)s->tick)((uint32_t)n);
        }
        s->k = ((take_fn)s->take)(s->txbuf, (uint16_t)s->txcap);
        if (s->k) {
            *reason = STOP_TX;
            return now + 1 - start;
        }
        if (s->until_tx && s->outbound_due <= t) {
            *reason = STOP_ARRIVED;
            return now + 1 - start;
        }
    }
    *reason = STOP_END;
    return now - start;
}
"""


class State(ctypes.Structure):
    """struct ms of SOURCE, field for field."""

    _fields_ = [
        *((name, ctypes.c_double) for name in
          ("t", "travelled", "v_left", "v_right", "theta", "x", "z", "dt", "a", "sag", "push",
           "wheelbase")),
        ("gain", ctypes.c_double * 2), ("offset", ctypes.c_double * 2),
        ("traction", ctypes.c_double * 2),
        *((name, ctypes.c_double) for name in ("slip", "v_max", "dead_zone", "span",
                                                "emu_now")),
        ("ticked", ctypes.c_int64), ("latency", ctypes.c_int64),
        ("applied", ctypes.c_int32 * 2), ("queued", ctypes.c_int32 * 2),
        ("pend_due", ctypes.c_int64 * PENDING), ("pend_m", (ctypes.c_int32 * 2) * PENDING),
        ("pend_head", ctypes.c_int32), ("pend_len", ctypes.c_int32),
        ("in_len", ctypes.c_int32), ("in_used", ctypes.c_int32),
        ("in_due", ctypes.c_double * INBOUND), ("in_byte", ctypes.c_uint8 * INBOUND),
        ("outbound_due", ctypes.c_double), ("until_tx", ctypes.c_int32),
        *((name, ctypes.c_void_p) for name in ("guard", "tick", "take", "motors", "rx", "draw",
                                               "draw_state")),
        ("txbuf", ctypes.c_void_p), ("txcap", ctypes.c_int32), ("k", ctypes.c_int32),
    ]


_lib: ctypes.CDLL | None = None
_tried = False
_failed: BuildFailed | None = None  # a build that failed fails every call, not the first only


def library() -> ctypes.CDLL | None:
    """The compiled run_ms (built once into the user cache, keyed by its source), or None
    where it cannot be built (no gcc) or STEREO_SERVO_NO_FAST_MS is set: the caller's Python
    loop then runs, the same steps. Code of ours that does not compile is BuildFailed."""
    global _lib, _tried, _failed
    if _failed is not None:
        raise _failed
    if _tried:
        return _lib
    _tried = True
    if os.environ.get("STEREO_SERVO_NO_FAST_MS") or shutil.which("gcc") is None:
        return None
    flags = ["-std=gnu11", "-O2", "-shared", "-fPIC", "-fno-builtin", "-ffp-contract=off",
             "-fno-fast-math", "-Wall", "-Wextra", "-Werror"]
    key = hashlib.sha256((SOURCE + " ".join(flags)).encode()).hexdigest()[:16]
    lib = CACHE / f"fast-ms-{key}.so"
    if not lib.exists():
        CACHE.mkdir(parents=True, exist_ok=True)
        src = lib.with_suffix(f".{os.getpid()}.c")
        tmp = lib.with_suffix(f".{os.getpid()}.tmp")
        src.write_text(SOURCE)
        r = subprocess.run(["gcc", *flags, str(src), "-o", str(tmp), "-lm"],
                           capture_output=True, text=True)
        src.unlink()
        if r.returncode:
            _failed = BuildFailed(f"building the compiled millisecond failed: {r.stderr[:300]}")
            raise _failed
        os.replace(tmp, lib)
    _lib = ctypes.CDLL(str(Path(lib)))
    _lib.run_ms.argtypes = [ctypes.POINTER(State), ctypes.c_int64, ctypes.c_int64,
                            ctypes.c_int64, ctypes.POINTER(ctypes.c_int32)]
    _lib.run_ms.restype = ctypes.c_int64
    return _lib

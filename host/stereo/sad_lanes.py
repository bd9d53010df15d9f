# mypy: disallow-untyped-defs=False, disallow-incomplete-defs=False, disallow-untyped-calls=False
# mypy: disable-error-code="call-arg,unreachable,var-annotated"
# (the relaxations pyproject.toml gives the numba kernels and lanes.py: the intrinsics are
# declared with numba's typing context as their first parameter)
"""Sixteen uint16 lanes as one numba value (an LLVM <16 x i16> vector) for the SAD kernel.

sad.py's loops over candidates, written for LLVM's own vectoriser, ran a vector body and a
remainder whose shape LLVM chose per loop from its cost model; these helpers make the vector
explicit, so a loop over candidates is ceil(n / 16) vector steps at every n. (lanes.py does
the same for the SGM kernels; this file is the SAD kernel's own, with the widening byte load,
the absolute difference and the first-equal lane it needs.)

Arrays are C-contiguous, of any dimension, indexed by the flat element index i (row * cols +
col for a 2-D array); nothing is bounds-checked: the caller keeps i + 16 within the array.

load(a, i) / store(a, i, v): lanes a[i .. i + 16] of a uint16 array. widen(a, i): bytes
a[i .. i + 16] of a uint8 array as uint16 lanes. splat(x): x in every lane. iota(k): lanes
k, k + 1, .., k + 15. vadd, vsub, vmin, vor, absdiff: per lane, wrapping like uint16.
hmin(v): the smallest lane. first_eq(v, x): the lowest lane equal to x, 16 if none.
take_le(c, low, a, b): lane j is a's where c <= low (unsigned), else b's.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic, models, register_model

LANES = 16
_I16 = ir.IntType(16)
_I8 = ir.IntType(8)
_I32 = ir.IntType(32)
_VEC = ir.VectorType(_I16, LANES)
_BYTES = ir.VectorType(_I8, LANES)


class U16Lanes(types.Type):
    """The numba type of sixteen uint16 lanes."""

    def __init__(self) -> None:
        super().__init__(name="SadU16x16")


u16lanes = U16Lanes()


@register_model(U16Lanes)
class _U16LanesModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _VEC)


def _array_of(a, dtype) -> bool:
    return isinstance(a, types.Array) and a.dtype == dtype and a.layout == "C"


def _ptr(context, builder, arrty, arr, i):
    a = context.make_array(arrty)(context, builder, arr)
    return builder.gep(a.data, [i])


def _broadcast(builder, s):
    v = builder.insert_element(ir.Constant(_VEC, ir.Undefined), s, ir.Constant(_I32, 0))
    return builder.shuffle_vector(v, ir.Constant(_VEC, ir.Undefined),
                                  ir.Constant(ir.VectorType(_I32, LANES), [0] * LANES))


def _to_i16(builder, x):
    w = x.type.width
    return builder.trunc(x, _I16) if w > 16 else (builder.zext(x, _I16) if w < 16 else x)


@intrinsic
def load(typingctx, a, i):
    if not (_array_of(a, types.uint16) and isinstance(i, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        p = builder.bitcast(_ptr(context, builder, sig.args[0], args[0], args[1]),
                            _VEC.as_pointer())
        return builder.load(p, align=2, typ=_VEC)
    return u16lanes(a, i), codegen


@intrinsic
def store(typingctx, a, i, v):
    if not (_array_of(a, types.uint16) and isinstance(i, types.Integer) and v == u16lanes):
        return None

    def codegen(context, builder, sig, args):
        p = builder.bitcast(_ptr(context, builder, sig.args[0], args[0], args[1]),
                            _VEC.as_pointer())
        builder.store(args[2], p, align=2)
        return context.get_dummy_value()
    return types.none(a, i, v), codegen


@intrinsic
def widen(typingctx, a, i):
    if not (_array_of(a, types.uint8) and isinstance(i, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        p = builder.bitcast(_ptr(context, builder, sig.args[0], args[0], args[1]),
                            _BYTES.as_pointer())
        return builder.zext(builder.load(p, align=1, typ=_BYTES), _VEC)
    return u16lanes(a, i), codegen


@intrinsic
def splat(typingctx, x):
    if not isinstance(x, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        return _broadcast(builder, _to_i16(builder, args[0]))
    return u16lanes(x), codegen


@intrinsic
def iota(typingctx, k):
    if not isinstance(k, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        return builder.add(_broadcast(builder, _to_i16(builder, args[0])),
                           ir.Constant(_VEC, list(range(LANES))))
    return u16lanes(k), codegen


def _binary(op):
    @intrinsic
    def fn(typingctx, a, b):
        if not (a == u16lanes and b == u16lanes):
            return None

        def codegen(context, builder, sig, args):
            return op(builder, args[0], args[1])
        return u16lanes(a, b), codegen
    return fn


def _umin(b, x, y):
    return b.select(b.icmp_unsigned("<", x, y), x, y)


def _umax(b, x, y):
    return b.select(b.icmp_unsigned(">", x, y), x, y)


vadd = _binary(lambda b, x, y: b.add(x, y))
vsub = _binary(lambda b, x, y: b.sub(x, y))
vor = _binary(lambda b, x, y: b.or_(x, y))
vmin = _binary(_umin)
absdiff = _binary(lambda b, x, y: b.sub(_umax(b, x, y), _umin(b, x, y)))


@intrinsic
def hmin(typingctx, v):
    if v != u16lanes:
        return None

    def codegen(context, builder, sig, args):
        fnty = ir.FunctionType(_I16, [_VEC])
        fn = cgutils.get_or_insert_function(builder.module, fnty,
                                            "llvm.vector.reduce.umin.v16i16")
        return builder.call(fn, [args[0]])
    return types.uint16(v), codegen


@intrinsic
def first_eq(typingctx, v, x):
    if not (v == u16lanes and isinstance(x, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        eq = builder.icmp_unsigned("==", args[0], _broadcast(builder, _to_i16(builder, args[1])))
        bits = builder.bitcast(eq, _I16)
        fnty = ir.FunctionType(_I16, [_I16, ir.IntType(1)])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "llvm.cttz.i16")
        n = builder.call(fn, [bits, ir.Constant(ir.IntType(1), 0)])
        return builder.zext(n, ir.IntType(64))
    return types.int64(v, x), codegen


@intrinsic
def take_le(typingctx, c, low, a, b):
    if not (c == u16lanes and low == u16lanes and a == u16lanes and b == u16lanes):
        return None

    def codegen(context, builder, sig, args):
        return builder.select(builder.icmp_unsigned("<=", args[0], args[1]), args[2], args[3])
    return u16lanes(c, low, a, b), codegen

"""Sixteen uint16 lanes as one numba value (an LLVM <16 x i16> vector) for the SGM kernels.

LLVM's own vectoriser picks its vector width and unrolling per loop from a cost model, and a
loop whose trip count is below that unroll (e.g. 48 of 64) runs scalar: the aggregation was
2.5x slower at 48 candidates than at 64. These helpers make the vector explicit, so a loop over
candidates runs ceil(n / 16) vector steps whatever n is. A vector is 256 bits (AVX2; AVX-512
machines run it at the same rate, and SSE2 machines as two halves).

load(a, i) / store(a, i, v): lanes a[i .. i + 16] of a C-contiguous uint16 array (no bounds
check: the caller keeps i + 16 <= a.size). splat(x): x in every lane. vmin, vadd, vsub: per
lane, wrapping like uint16. hmin(v): the smallest lane. select_ge(k, a, b): lane j takes a's
lane where j >= k, else b's.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic, models, register_model

LANES = 16
_I16 = ir.IntType(16)
_VEC = ir.VectorType(_I16, LANES)


class U16x16(types.Type):
    """The numba type of sixteen uint16 lanes."""

    def __init__(self) -> None:
        super().__init__(name="U16x16")


u16x16 = U16x16()


@register_model(U16x16)
class _U16x16Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _VEC)


def _lane_ptr(context, builder, arrty, arr, i):
    a = context.make_array(arrty)(context, builder, arr)
    return builder.gep(a.data, [i])


def _uint16_array(a) -> bool:
    return isinstance(a, types.Array) and a.dtype == types.uint16 and a.layout == "C"


@intrinsic
def load(typingctx, a, i):
    if not (_uint16_array(a) and isinstance(i, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        ptr = _lane_ptr(context, builder, sig.args[0], args[0], args[1])
        vp = builder.bitcast(ptr, _VEC.as_pointer())
        return builder.load(vp, align=2, typ=_VEC)
    return u16x16(a, i), codegen


@intrinsic
def store(typingctx, a, i, v):
    if not (_uint16_array(a) and isinstance(i, types.Integer) and v == u16x16):
        return None

    def codegen(context, builder, sig, args):
        ptr = _lane_ptr(context, builder, sig.args[0], args[0], args[1])
        vp = builder.bitcast(ptr, _VEC.as_pointer())
        builder.store(args[2], vp, align=2)
        return context.get_dummy_value()
    return types.none(a, i, v), codegen


@intrinsic
def splat(typingctx, x):
    if not isinstance(x, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        s = builder.trunc(args[0], _I16) if args[0].type.width > 16 else (
            builder.zext(args[0], _I16) if args[0].type.width < 16 else args[0])
        v = builder.insert_element(ir.Constant(_VEC, ir.Undefined), s, ir.Constant(
            ir.IntType(32), 0))
        return builder.shuffle_vector(v, ir.Constant(_VEC, ir.Undefined),
                                      ir.Constant(ir.VectorType(ir.IntType(32), LANES),
                                                  [0] * LANES))
    return u16x16(x), codegen


def _binary(op):
    @intrinsic
    def fn(typingctx, a, b):
        if not (a == u16x16 and b == u16x16):
            return None

        def codegen(context, builder, sig, args):
            return op(builder, args[0], args[1])
        return u16x16(a, b), codegen
    return fn


vmin = _binary(lambda b, x, y: b.select(b.icmp_unsigned("<", x, y), x, y))
vadd = _binary(lambda b, x, y: b.add(x, y))
vsub = _binary(lambda b, x, y: b.sub(x, y))


def _reduce_umin(builder, v):
    fnty = ir.FunctionType(_I16, [_VEC])
    fn = cgutils.get_or_insert_function(builder.module, fnty, "llvm.vector.reduce.umin.v16i16")
    return builder.call(fn, [v])


@intrinsic
def hmin(typingctx, v):
    if v != u16x16:
        return None

    def codegen(context, builder, sig, args):
        return _reduce_umin(builder, args[0])
    return types.uint16(v), codegen


def _iota(builder):
    return ir.Constant(_VEC, list(range(LANES)))


@intrinsic
def select_ge(typingctx, k, a, b):
    if not (a == u16x16 and b == u16x16 and isinstance(k, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        kk = builder.trunc(args[0], _I16) if args[0].type.width > 16 else args[0]
        kv = builder.shuffle_vector(
            builder.insert_element(ir.Constant(_VEC, ir.Undefined), kk,
                                   ir.Constant(ir.IntType(32), 0)),
            ir.Constant(_VEC, ir.Undefined),
            ir.Constant(ir.VectorType(ir.IntType(32), LANES), [0] * LANES))
        take = builder.icmp_unsigned(">=", _iota(builder), kv)
        return builder.select(take, args[1], args[2])
    return u16x16(k, a, b), codegen

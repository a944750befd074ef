"""The numba step loop for FMI 3.0 co-simulation, the FMU's functions called by plain addresses.

The FMI 2.0 loop (``steploop_compiled``) with FMI 3.0's signatures: the getter and setter take
the number of values too, and ``fmi3DoStep`` writes four results through pointers (event
handling needed, terminate, early return, last successful time). Those land in ``flags`` (three
bytes) and a double the caller owns; the loop stops when the FMU asks to terminate. Kept apart
so numba is imported only once the Python loop has run long enough (``fmi3._step_loop``).
"""

from __future__ import annotations

from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

_I8, _I8P, _I32, _I64, _F64 = ir.IntType(8), ir.IntType(8).as_pointer(), ir.IntType(32), ir.IntType(64), ir.DoubleType()
# fmi3Status fmi3SetFloat64/fmi3GetFloat64(fmi3Instance, const fmi3ValueReference[], size_t, fmi3Float64[], size_t)
_FLOAT64_IO = ir.FunctionType(_I32, [_I8P, _I8P, _I64, _I8P, _I64])
# fmi3Status fmi3DoStep(fmi3Instance, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
#                       fmi3Boolean*, fmi3Boolean*, fmi3Boolean*, fmi3Float64*)
_DO_STEP = ir.FunctionType(_I32, [_I8P, _F64, _F64, _I8, _I8P, _I8P, _I8P, _I8P])


@intrinsic
def call_float64_io(typingctx, address, instance, vr, n, values):
    def codegen(context, builder, signature, args):
        address, instance, vr, n, values = args
        function = builder.inttoptr(address, _FLOAT64_IO.as_pointer())
        return builder.call(
            function,
            [builder.inttoptr(instance, _I8P), builder.inttoptr(vr, _I8P), n, builder.inttoptr(values, _I8P), n],
        )

    return types.int32(types.intp, types.intp, types.intp, types.intp, types.intp), codegen


@intrinsic
def call_do_step(typingctx, address, instance, t, h, flags, last_time):
    def codegen(context, builder, signature, args):
        address, instance, t, h, flags, last_time = args
        function = builder.inttoptr(address, _DO_STEP.as_pointer())
        event = builder.inttoptr(flags, _I8P)
        terminate = builder.inttoptr(builder.add(flags, ir.Constant(_I64, 1)), _I8P)
        early = builder.inttoptr(builder.add(flags, ir.Constant(_I64, 2)), _I8P)
        return builder.call(
            function,
            [builder.inttoptr(instance, _I8P), t, h, ir.Constant(_I8, 1), event, terminate, early,
             builder.inttoptr(last_time, _I8P)],
        )

    return types.int32(types.intp, types.intp, types.float64, types.float64, types.intp, types.intp), codegen


_i, _f = types.intp, types.float64
_flags = types.Array(types.uint8, 1, "C")


@njit(types.UniTuple(_i, 3)(_i, _i, _i, _i, _i, _i, _i, _i, _i, _i, _i, _i, _f, _f, _f, _i, _i, _i, _flags, _i),
      cache=True, nogil=True)
def loop(set_float64, get_float64, do_step, instance, input_vr, n_inputs, in_base, in_stride,
         output_vr, n_outputs, out_base, out_stride, t0, h, last_h, n_steps, first, last, flags, last_time):
    """Steps ``first``..``last``-1: set inputs, get outputs, step; (step, which, status) on an error,
    which 1-3 naming the function, 4 a request to terminate."""
    flags_address = flags.ctypes.data
    for k in range(first, last):
        if n_inputs:
            status = call_float64_io(set_float64, instance, input_vr, n_inputs, in_base + k * in_stride)
            if status > 1:
                return k, 1, status
        status = call_float64_io(get_float64, instance, output_vr, n_outputs, out_base + k * out_stride)
        if status > 1:
            return k, 2, status
        status = call_do_step(do_step, instance, t0 + k * h, h if k < n_steps - 1 else last_h, flags_address, last_time)
        if status > 1:
            return k, 3, status
        if flags[1]:
            return k, 4, status
    return last, 0, 0

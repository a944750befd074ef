"""The numba step loop, with the FMU's functions called by plain integer addresses.

Kept apart from ``steploop`` so numba is imported only when the compiled loop is wanted, and at
module level so numba's disk cache finds the compiled loop again in the next process (a loop
defined inside a function, closing over its helpers, is compiled anew every time).

The addresses are ordinary ``intp`` arguments: numba types an integer for free, whereas a
function-pointer object is re-typed on every call (about 33 µs). Pointers and ``size_t`` are
64-bit integers on the platforms FMUs ship for.
"""

from __future__ import annotations

from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

_I8P, _I32, _I64, _F64 = ir.IntType(8).as_pointer(), ir.IntType(32), ir.IntType(64), ir.DoubleType()
# fmi2Status fmi2SetReal/fmi2GetReal(fmi2Component, const fmi2ValueReference*, size_t, fmi2Real*)
_REAL_IO = ir.FunctionType(_I32, [_I8P, _I8P, _I64, _I8P])
# fmi2Status fmi2DoStep(fmi2Component, fmi2Real t, fmi2Real h, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
_DO_STEP = ir.FunctionType(_I32, [_I8P, _F64, _F64, _I32])


@intrinsic
def call_real_io(typingctx, address, component, vr, n, values):
    def codegen(context, builder, signature, args):
        address, component, vr, n, values = args
        function = builder.inttoptr(address, _REAL_IO.as_pointer())
        return builder.call(
            function,
            [builder.inttoptr(component, _I8P), builder.inttoptr(vr, _I8P), n, builder.inttoptr(values, _I8P)],
        )

    return types.int32(types.intp, types.intp, types.intp, types.intp, types.intp), codegen


@intrinsic
def call_do_step(typingctx, address, component, t, h):
    def codegen(context, builder, signature, args):
        address, component, t, h = args
        function = builder.inttoptr(address, _DO_STEP.as_pointer())
        return builder.call(function, [builder.inttoptr(component, _I8P), t, h, ir.Constant(_I32, 1)])

    return types.int32(types.intp, types.intp, types.float64, types.float64), codegen


_i, _f = types.intp, types.float64


@njit(types.UniTuple(_i, 3)(_i, _i, _i, _i, _i, _i, _i, _i, _i, _i, _i, _i, _f, _f, _f, _i, _i, _i),
      cache=True, nogil=True)
def loop(set_real, get_real, do_step, component, input_vr, n_inputs, in_base, in_stride,
         output_vr, n_outputs, out_base, out_stride, t0, h, last_h, n_steps, first, last):
    """Steps ``first``..``last``-1: set inputs, get outputs, step; (step, which function, status) on an error."""
    for k in range(first, last):
        if n_inputs:
            status = call_real_io(set_real, component, input_vr, n_inputs, in_base + k * in_stride)
            if status > 1:
                return k, 1, status
        status = call_real_io(get_real, component, output_vr, n_outputs, out_base + k * out_stride)
        if status > 1:
            return k, 2, status
        status = call_do_step(do_step, component, t0 + k * h, h if k < n_steps - 1 else last_h)
        if status > 1:
            return k, 3, status
    return last, 0, 0

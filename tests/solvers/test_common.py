"""solvers._common: the arrays Python hands the compiled kernels are the loop's types."""
from types import SimpleNamespace

import numpy as np

from nonsmooth_rod.solvers._common import loop_array, python_body


def test_loop_array_passes_the_loops_own_arrays_through_and_copies_the_others():
    """C-contiguous writable float64/int64 (what the loop passes, one compiled signature): the same
    object, so an output filled in place stays the caller's; readonly, strided or another dtype —
    each a new numba signature, a new compile of the kernel's subtree — copied to that type."""
    a = np.arange(3.0)
    assert loop_array(a) is a
    ints = np.arange(3)
    assert loop_array(ints.astype(np.int64), np.int64).dtype == np.int64
    readonly = np.arange(3.0)
    readonly.flags.writeable = False
    for other in (readonly, np.arange(6.0)[::2], np.arange(3, dtype=np.int32), np.asfortranarray(np.arange(6.0).reshape(2, 3))):
        copy = loop_array(other)
        assert copy is not other and copy.dtype == np.float64
        assert copy.flags.c_contiguous and copy.flags.writeable
        np.testing.assert_array_equal(copy, other)
    assert loop_array(np.arange(3, dtype=np.int32), np.int64).dtype == np.int64


def test_python_body_is_the_kernels_source():
    def kernel(x):
        return 2 * x

    dispatcher = SimpleNamespace(py_func=kernel)  # numba's dispatchers (and _jit.LazyKernel): the source
    assert python_body(dispatcher) is kernel
    assert python_body(kernel) is kernel  # without numba the kernel is the function itself

"""shellform's numba code: compiled once, cached on disk under a key of the sources.

numba's own cache checks only the file of the function it compiles, not the files of the
functions it calls: an edit of hill79.py would leave the compiled section update, which calls
it, stale. So every numba function of the package is cached in a folder named by a hash of all
the package's modules that hold numba code: an edit of any of them recompiles them once, and
a fresh process otherwise loads machine code instead of compiling (about 30 s saved on every
run of the sheet).

The folder is NUMBA_CACHE_DIR/shellform-HASH when the user sets NUMBA_CACHE_DIR, else
~/.cache/shellform/numba/HASH (XDG_CACHE_HOME respected). Other numba code in the process keeps
its own cache location.

The FFCx kernels are called through their addresses, passed as integers (``call_kernel``), so
that the loops around them hold no address of this process and can be cached too. They are
compiled for this CPU (-O3 -march=native: the sheet's tangent kernel 27-29 -> 22-24 us per
cell) into a cache of this CPU model's own (FFCX_JIT_OPTIONS), so that a home directory shared
by machines of other CPUs never loads code their CPU cannot run.

The loops over the cells run on threads without numba's parallel=True: each is a numba function
compiled with nogil=True that takes chunks of cells from a counter its threads share
(next_chunk), run at once on a small pool of Python threads (over_threads), and it takes its
arrays without their reference counts (borrowed), so that its threads do not contend for them.
What a cold first run compiles is kept small (docs/performance.md, "Where a cold first run's time
goes"): no parfor passes, no formatted error messages (no array-from-array slice assignment,
whose shape check formats one), division by zero as numpy's (OPTIONS).
"""

import hashlib
import os
import threading
from concurrent.futures import ThreadPoolExecutor, wait
from pathlib import Path

import numba
import numpy as np
from llvmlite import binding, ir
from numba import types
from numba.extending import intrinsic

_PACKAGE = Path(__file__).resolve().parent
_NUMBA_MODULES = ("_jit.py", "assembly", "material", "nonlinear/frames.py", "tools/face_kernels.py",
                  "tools/mesh_patches.py", "nonlinear/model.py", "nonlinear/assemble.py")


def _source_key() -> str:
    h = hashlib.sha256(numba.__version__.encode())
    for entry in _NUMBA_MODULES:
        path = _PACKAGE / entry
        for f in sorted(path.rglob("*.py")) if path.is_dir() else [path]:
            h.update(f.relative_to(_PACKAGE).as_posix().encode())
            h.update(f.read_bytes())
    return h.hexdigest()[:16]


def cache_dir() -> Path:
    key = _source_key()
    user = os.environ.get("NUMBA_CACHE_DIR")
    if user:
        return Path(user) / f"shellform-{key}"
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "shellform" / "numba" / key


_CACHE_DIR = str(cache_dir())


def compiled() -> bool:
    """Whether this version's element kernels were compiled on this machine before: the sheet's
    tangent loop, the dearest of them, is in the cache folder (other functions, such as those a
    scene's checks call, may be there without it). A run without them compiles first."""
    folder = Path(_CACHE_DIR)
    return folder.is_dir() and any(folder.rglob("sheet_kernels.tensor_loop-*.nbi"))


def _cpu_key() -> str:
    """This CPU's model and features, as -march=native sees them (LLVM's host description)."""
    h = hashlib.sha256(binding.get_host_cpu_name().encode())
    h.update(binding.get_host_cpu_features().flatten().encode())
    return h.hexdigest()[:12]


def _ffcx_cache_dir() -> Path:
    base = Path(os.getenv("XDG_CACHE_HOME", Path.home() / ".cache"))
    return base / "fenics" / f"shellform-native-{_cpu_key()}"


# jit_options of every FFCx kernel of the package (FFCx's default is -O2, generic x86-64)
FFCX_JIT_OPTIONS = {"cffi_extra_compile_args": ["-O3", "-g0", "-march=native"], "cache_dir": _ffcx_cache_dir()}


# numba options of every function of the package unless it names others: a division by zero
# gives inf or nan, as numpy's (the material loops report a point that is not finite; numba's
# default raises ZeroDivisionError, a check and an exception path compiled at every division),
# and no C callback wrapper (no function is passed to C as a cfunc)
OPTIONS = {"error_model": "numpy", "no_cfunc_wrapper": True}


def njit(*args, **options):
    """numba.njit(cache=True, **OPTIONS, ...) with the cache in shellform's source-keyed folder
    (numba binds a function to its cache folder when it is decorated)."""

    def decorate(f):
        saved = numba.config.CACHE_DIR
        numba.config.CACHE_DIR = _CACHE_DIR
        try:
            return numba.njit(cache=True, **{**OPTIONS, **options})(f)
        finally:
            numba.config.CACHE_DIR = saved

    if args and callable(args[0]):
        return decorate(args[0])
    return decorate


@intrinsic
def call_kernel(typingctx, address, A, w, c, coords, local, perm):
    """The UFCx kernel at `address` (an integer) on the arrays' data:
    void tabulate_tensor(double *A, const double *w, const double *c, const double *coords,
                         const int *local_index, const uint8_t *permutation, void *custom_data)
    with custom_data NULL."""
    arrays = (A, w, c, coords, local, perm)
    dtypes = (types.float64,) * 4 + (types.int32, types.uint8)
    if not isinstance(address, types.Integer) or any(
            not isinstance(a, types.Array) or a.dtype != d for a, d in zip(arrays, dtypes)):
        return None
    sig = types.void(address, A, w, c, coords, local, perm)

    def codegen(context, builder, signature, args):
        double, i32, i8 = ir.DoubleType(), ir.IntType(32), ir.IntType(8)
        fnty = ir.FunctionType(ir.VoidType(), [double.as_pointer()] * 4 + [i32.as_pointer(), i8.as_pointer(),
                                                                            i8.as_pointer()])
        fn = builder.inttoptr(args[0], fnty.as_pointer())
        data = [context.make_array(t)(context, builder, v).data for t, v in zip(signature.args[1:], args[1:])]
        data = [builder.bitcast(d, fnty.args[i]) for i, d in enumerate(data)]
        builder.call(fn, data + [ir.Constant(i8.as_pointer(), None)])
        return context.get_dummy_value()

    return sig, codegen


def kernel_address(kernel) -> int:
    """The address of a cffi kernel pointer (FFCx's tabulate_tensor_float64) as an integer."""
    import cffi

    return int(cffi.FFI().cast("uintptr_t", kernel))


CHUNK = 16  # cells a thread takes at a time from a loop's shared counter (next_chunk)

_pool, _pool_size, _pool_lock = None, 0, threading.Lock()


def over_threads(share, nt: int, *args) -> list:
    """[share(counter, *args) on each of nt threads], run at once: one on the calling thread,
    the others on a pool of nt - 1 threads kept for the process. ``share`` is a numba function
    compiled with nogil=True that takes the chunks of its loop from the shared counter
    (next_chunk) until none is left, so the threads run on separate cores and one that starts
    late or is held up does fewer chunks. Plain numba functions on a Python pool instead of
    numba's parallel=True: numba compiles a prange loop through its parfor passes, which cost
    more compile time than the loops themselves (docs/performance.md, issue 44). Returns once
    every share has ended; an error of a share is raised after that."""
    counter = np.zeros(1, dtype=np.int64)
    if nt <= 1:
        return [share(counter, *args)]
    global _pool, _pool_size
    with _pool_lock:
        if _pool_size < nt - 1:
            if _pool is not None:
                _pool.shutdown(wait=False)
            _pool, _pool_size = ThreadPoolExecutor(nt - 1, thread_name_prefix="shellform-cells"), nt - 1
        pool = _pool
    futures = [pool.submit(share, counter, *args) for _ in range(1, nt)]
    try:
        first = share(counter, *args)
    finally:
        wait(futures)  # every share ends before the arrays are touched again
    return [first] + [f.result() for f in futures]


@intrinsic
def next_chunk(typingctx, counter):
    """The first item of the next chunk of CHUNK items of a loop whose threads share `counter`
    (an int64 array, its element 0 the next item not yet taken): an atomic add. The loop ends
    where this is past its last item."""
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64):
        return None

    def codegen(context, builder, signature, args):
        ary = context.make_array(signature.args[0])(context, builder, args[0])
        return builder.atomic_rmw("add", ary.data, ir.Constant(ir.IntType(64), CHUNK), "seq_cst")

    return types.int64(counter), codegen


@intrinsic
def borrowed(typingctx, a):
    """The array `a` without its reference count (its meminfo NULL): the views taken from it in
    a loop then count no references either (an atomic add to the array's one counter per view,
    which threads working on the same array contend for). Only for an array that its caller
    keeps alive for the call, and never returned or stored."""
    if not isinstance(a, types.Array):
        return None

    def codegen(context, builder, signature, args):
        ary = context.make_array(signature.args[0])(context, builder, args[0])
        ary.meminfo = context.get_constant_null(types.MemInfoPointer(types.voidptr))
        return ary._getvalue()

    return a(a), codegen

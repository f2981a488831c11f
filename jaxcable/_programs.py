"""Compiled programs kept on disk by the structure of their arguments, for the command
line's runs: a second `jaxcable run` of a scene with the same structure loads them
without tracing them again.

JAX's persistent compilation cache keys a program by its lowered module, so a process
must trace and lower a program before it can look it up. For the Low & Langley file that
was 2.6 s of a 5.1 s warm `jaxcable run` (statics' and the blocks' programs traced in
1.2 s, lowered in 1.0 s, loaded in 0.4 s; MoorDyn's whole process takes 3.7 s). Here
a program is keyed instead by everything its trace depends on, which is known before
tracing:

- the function, jaxcable's source code and the versions of JAX and the libraries it
  is built on;
- JAX's configuration that changes a trace or its compilation (64-bit types, type
  promotion, matmul precision, `XLA_FLAGS`) and the device (platform, kind, and the
  CPU's instruction set: an executable uses the instructions of the machine that
  compiled it);
- the arguments' structure: the shape, dtype and weak type of every array, and the value
  of everything else (static fields such as the network's topology, options, integers).

The key is a digest of all of that; the executable is serialised
(`jax.experimental.serialize_executable`) under it and loaded back directly. Where an
argument holds a value the key cannot describe exactly (a closure, say), or is traced
(the program called inside another's trace, or under `vmap`), the call is
`eqx.filter_jit`'s, as it is whenever no folder is set.

The folder is the same for the library and the command line ([`default_folder`][]:
`~/.cache/jaxcable/xla/jaxcable-programs` unless the environment says otherwise), so
that a script's second process loads `solve_statics`' and `run_scene`'s programs as a
second `jaxcable run` does; [`use_folder`][] sets another, or none. The library never
changes JAX's own configuration for it: JAX's cache, for the programs not kept here,
is the command line's to switch on.

A program can also be compiled ahead, in a background thread ([`Program.prepare`][]):
XLA compiles on threads of its own, without Python's lock, so programs compile while
Python traces the next.
"""

import concurrent.futures
import contextlib
import dataclasses
import enum
import functools
import hashlib
import importlib.metadata
import io
import os
import pickle
import platform
import sys
import tempfile
import threading
import time
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

import equinox as eqx
import jax
import numpy as np
from jax import monitoring
from jax.core import Tracer
from jax.experimental import serialize_executable

_JAX_CACHE_HIT = "/jax/compilation_cache/cache_hits"
_JAX_CACHE_MISS = "/jax/compilation_cache/cache_misses"
_hits = threading.local()  # JAX's cache hits and misses in this thread, counted by `_count_hits`


def _count_hits(event: str, **_) -> None:
    if event == _JAX_CACHE_HIT:
        _hits.count = getattr(_hits, "count", 0) + 1
    elif event == _JAX_CACHE_MISS:
        _hits.misses = getattr(_hits, "misses", 0) + 1


# JAX records its cache's hits in the compiling thread, so a count per thread tells
# which of the programs compiling at once (`Program.prepare`) came from it.
monitoring.register_event_listener(_count_hits)

LOADED_EVENT = "/jaxcable/programs/loaded"
"""Recorded (`jax.monitoring`) for each program loaded from the folder."""

COMPILED_EVENT = "/jaxcable/programs/compiled"
"""Recorded for each program compiled because neither the folder nor JAX's cache had it,
where JAX recorded no cache miss of its own (it records none for a program compiled
past its cache, as `Program._compile` does)."""

WAIT_EVENT = "/jaxcable/programs/wait"
"""A time span recorded while a call waits for its program's compilation in the background."""

_LIBRARIES = ("jax", "jaxlib", "equinox", "diffrax", "optimistix", "lineax", "numpy")
_CONFIG = (
    "jax_enable_x64",
    "jax_default_matmul_precision",
    "jax_numpy_rank_promotion",
    "jax_numpy_dtype_promotion",
    "jax_default_prng_impl",
)
_SUFFIX = ".program"

_folder: Path | None = None
_chosen = False  # whether `_folder` is set; until then `folder()` reads the default
_lock = threading.Lock()
_executor: concurrent.futures.ThreadPoolExecutor | None = None


def cache_root() -> Path | None:
    """The folder of jaxcable's compilation caches: `$JAX_COMPILATION_CACHE_DIR` where
    set (the caller's own cache for JAX), else `$JAXCABLE_CACHE_DIR`, else `jaxcable/xla`
    under `$XDG_CACHE_HOME` (`~/.cache` by default); `None` where `JAXCABLE_CACHE_DIR`
    is empty (caching off)."""
    root = os.environ.get("JAX_COMPILATION_CACHE_DIR")
    if root is None:
        root = os.environ.get("JAXCABLE_CACHE_DIR")
        if root is None:
            root = str(Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "jaxcable" / "xla")
    return Path(root) if root else None


def default_folder() -> Path | None:
    """Where programs are kept unless [`use_folder`][] says otherwise: `jaxcable-programs`
    in [`cache_root`][], or nowhere where caching is off."""
    root = cache_root()
    return None if root is None else root / "jaxcable-programs"


def use_folder(folder: str | os.PathLike | None) -> None:
    """Keep programs in `folder` (created when first written), or nowhere (`None`)."""
    global _folder, _chosen
    _folder, _chosen = (None if folder is None else Path(folder)), True


def folder() -> Path | None:
    """The folder programs are kept in, or `None`: [`default_folder`][] until
    [`use_folder`][] sets another (read from the environment at the first call)."""
    global _folder, _chosen
    if not _chosen:
        _folder, _chosen = default_folder(), True
    return _folder


class _Uncacheable(Exception):
    """An argument the key cannot describe exactly."""


class Program:
    """`eqx.filter_jit(fn)`, whose compiled programs are also kept in the folder set by
    [`use_folder`][] (see the module's notes).

    Call it as `fn`. The outputs are those of the compiled program, the same arrays as
    `eqx.filter_jit`'s; a program loaded from the folder gives bitwise the same results,
    being the same executable.
    """

    def __init__(self, fn: Callable, compiler_options: dict[str, Any] | None = None):
        self.fn = fn
        self.name = f"{fn.__module__}.{fn.__qualname__}"
        self.compiler_options = dict(compiler_options or {})
        self._jit = eqx.filter_jit(fn)
        # JAX takes compiler options on a top-level program only, not on one traced into
        # another (the caller's `jit`, a sweep).
        jit_options: dict[str, Any] = {"compiler_options": self.compiler_options}
        self._top = eqx.filter_jit(fn, **jit_options) if compiler_options else self._jit
        self._programs: dict[str, Any] = {}  # key → (executable, output tree) or a Future of it
        self._shapes: dict[str, Any] = {}  # key → the outputs' shapes, from the lowering
        functools.update_wrapper(self, fn)

    def lower(self, *args, **kwargs):
        """`eqx.filter_jit(fn).lower`."""
        return self._jit.lower(*args, **kwargs)

    def __call__(self, *args, **kwargs):
        found = self._program(args, kwargs)
        if found is None:
            traced = any(isinstance(leaf, Tracer) for leaf in jax.tree.leaves((args, kwargs)))
            return (self._jit if traced else self._top)(*args, **kwargs)
        key, dynamic = found
        executable, tree = self._obtain(key, args, kwargs)
        return jax.tree.unflatten(tree, executable(*dynamic))

    def prepare(self, *args, **kwargs) -> None:
        """Start compiling the program for these arguments in a background thread, unless
        it is compiled or in the folder already; a later call with arguments of the same
        structure waits for it. Arrays may be given as `jax.ShapeDtypeStruct`. Does
        nothing where no folder is set."""
        found = self._program(args, kwargs)
        if found is None:
            return
        key = found[0]
        with _lock:
            if key in self._programs:
                return
        loaded = self._load(key)
        if loaded is not None:
            self._programs[key] = loaded
            return
        lowered, tree = self._lower(args, kwargs)
        self._shapes[key] = jax.tree.unflatten(tree, jax.tree.leaves(lowered.out_info))
        self._programs[key] = _background().submit(self._compile, key, lowered, tree)

    def output_shapes(self, *args, **kwargs):
        """The outputs' shapes and dtypes (`jax.ShapeDtypeStruct`s) for these arguments,
        from the program where it is known, else by `jax.eval_shape`."""
        found = self._program(args, kwargs)
        if found is not None:
            key = found[0]
            if key in self._shapes:
                return self._shapes[key]
            entry = self._programs.get(key)
            if isinstance(entry, tuple):
                executable, tree = entry
                return jax.tree.unflatten(tree, jax.tree.leaves(executable.out_info))
        return eqx.filter_eval_shape(self.fn, *args, **kwargs)

    def _program(self, args, kwargs) -> tuple[str, list] | None:
        """The key and the dynamic leaves (arrays) of these arguments, or `None` where
        they are not kept: no folder, a traced argument, or an argument the key cannot
        describe."""
        if folder() is None:
            return None
        leaves, tree = jax.tree.flatten((args, kwargs))
        if any(isinstance(leaf, Tracer) for leaf in leaves):
            return None
        # A program is compiled for the default device; arrays placed elsewhere (a
        # sweep's shards) take `eqx.filter_jit`'s path, which follows them.
        device = jax.devices()[0]
        if any(isinstance(leaf, jax.Array) and leaf.sharding.device_set != {device} for leaf in leaves):
            return None
        try:
            digest = hashlib.sha256(_environment())
            # Read on every call: a context manager may change them in one thread.
            digest.update(_encode([(name, str(getattr(jax.config, name))) for name in _CONFIG]))
            digest.update(os.environ.get("XLA_FLAGS", "").encode())
            digest.update(self.name.encode())
            digest.update(_encode(sorted(self.compiler_options.items())))
            digest.update(_encode(_describe_tree(tree)))
            dynamic = []
            for leaf in leaves:
                if _is_array(leaf):
                    dynamic.append(leaf)
                    digest.update(_array_key(tuple(leaf.shape), leaf.dtype, _weak(leaf)))
                else:
                    digest.update(_encode(("static", _describe(leaf))))
        except _Uncacheable:
            return None
        return digest.hexdigest(), dynamic

    def _obtain(self, key: str, args, kwargs):
        """The executable and output tree for `key`: in memory, compiling in the
        background, in the folder, or compiled now."""
        entry = self._programs.get(key)
        if isinstance(entry, concurrent.futures.Future):
            start = time.perf_counter()
            entry = entry.result()
            monitoring.record_event_time_span(WAIT_EVENT, start, time.perf_counter())
        if entry is None:
            entry = self._load(key)
        if entry is None:
            lowered, tree = self._lower(args, kwargs)
            entry = self._compile(key, lowered, tree)
        self._programs[key] = entry
        return entry

    def _lower(self, args, kwargs):
        """Trace and lower `fn` as a function of the dynamic leaves alone; also the
        outputs' tree, known once traced."""
        leaves, tree = jax.tree.flatten((args, kwargs))
        mask = [_is_array(leaf) for leaf in leaves]
        statics = [None if m else leaf for leaf, m in zip(leaves, mask)]
        out_tree = []

        def flat(*dynamic):
            it = iter(dynamic)
            full = [next(it) if m else s for m, s in zip(mask, statics)]
            call_args, call_kwargs = jax.tree.unflatten(tree, full)
            outputs, out = jax.tree.flatten(self.fn(*call_args, **call_kwargs))
            out_tree.append(out)
            return outputs

        flat.__name__ = flat.__qualname__ = self.fn.__name__  # JAX's logs and cache name it so
        dynamic = [_abstract(leaf) for leaf, m in zip(leaves, mask) if m]
        lowered = jax.jit(flat).lower(*dynamic)
        return lowered, out_tree[0]

    def _compile(self, key: str, lowered, tree):
        """Compile `lowered` and keep it, unless JAX's own cache supplied it: XLA's CPU
        client serialises an executable that it deserialised without some of its
        kernels, so the file would load but fail when run ("Function ... not found",
        jaxlib 0.10.2). That happens where JAX's cache outlives this folder's entry (a
        new jaxcable whose program lowers as before); JAX's cache still serves it."""
        _hits.count = _hits.misses = 0
        # Kept here, so not in JAX's cache as well: its compressed copy of statics' program
        # was written on a cold run's critical path, for nothing.
        with persistent_cache_threshold(float("inf")):
            executable = lowered.compile(self.compiler_options or None)
        if not _hits.count:
            if not _hits.misses:
                monitoring.record_event(COMPILED_EVENT)
            self._save(key, executable, tree)
        return executable, tree

    def _path(self, key: str) -> Path:
        kept = folder()
        assert kept is not None
        return kept / f"{self.fn.__qualname__}-{key[:40]}{_SUFFIX}"

    def _load(self, key: str):
        """The program kept under `key`, or `None`. A file that cannot be loaded (a
        partial write, another version's format) is removed, and the program compiled
        again."""
        if folder() is None:
            return None
        path = self._path(key)
        try:
            blob, in_tree, out_tree, tree = _loads(path.read_bytes())
            # On the device it was compiled for (`_program`'s): by default JAX loads an
            # executable onto every device, and where there are several (a sweep's
            # process) it then asks each argument for one shard per device.
            device = jax.devices()[0]
            executable = serialize_executable.deserialize_and_load(
                blob, in_tree, out_tree, backend=device.client, execution_devices=[device]
            )
        except FileNotFoundError:
            return None
        except Exception:  # noqa: BLE001 (any unreadable file is only a cache miss)
            path.unlink(missing_ok=True)
            return None
        monitoring.record_event(LOADED_EVENT)
        return executable, tree

    def _save(self, key: str, executable, tree) -> None:
        """Write the program under `key`, atomically; not where its output tree cannot
        be written and read back exactly (a node type pickle cannot rebuild), or the
        folder cannot be written (the run goes on: it only loses the cache)."""
        kept = folder()
        if kept is None:
            return
        try:
            blob, in_tree, out_tree = serialize_executable.serialize(executable)
            data = _dumps((blob, in_tree, out_tree, tree))
            if _loads(data)[3] != tree:
                return
            kept.mkdir(parents=True, exist_ok=True)
            with tempfile.NamedTemporaryFile(dir=kept, delete=False, suffix=".partial") as file:
                file.write(data)
            os.replace(file.name, self._path(key))
        except (OSError, pickle.PicklingError, TypeError, AttributeError):
            return


RUN_ONCE = {"xla_cpu_use_fusion_emitters": False, "xla_backend_optimization_level": 0}
"""XLA's options for a program that runs once or a few times a process, whose compile is
most of its cost: statics (`jaxcable._statics.solve._equilibrium`), the outputs. XLA's CPU
fusion emitters (its default) and LLVM's optimisations make kernels that run faster but
compile slower. For the Low & Langley file's statics, without them the compile takes
under half the CPU time and the run 2.3 times as long, still tens of milliseconds, so a
cold `jaxcable run` ends sooner."""


def persistent_cache_threshold(seconds: float) -> contextlib.AbstractContextManager:
    """A context manager: inside it, this thread keeps in JAX's persistent cache only
    the programs that take longer than `seconds` (s) to compile.

    JAX has no public per-thread switch (`jax.config.update` sets every thread's), so
    this is the one place jaxcable reaches into JAX's private modules;
    `tests/test_programs.py` fails if a JAX release moves it."""
    from jax._src import config

    return config.persistent_cache_min_compile_time_secs(seconds)


def program(fn: Callable, compiler_options: dict[str, Any] | None = None) -> Program:
    """Decorate `fn` as a [`Program`][]; `compiler_options` are XLA's options for this
    program alone (`jax.jit`'s), as `@functools.partial(program, compiler_options=...)`."""
    return Program(fn, compiler_options)


def _sentinels() -> dict[str, object]:
    """Objects that pytree nodes compare by identity, which pickle would copy: equinox's
    `MISSING`, in every module's static data. Without them (another equinox), an output
    tree does not read back equal and is not written (`Program._save`)."""
    try:
        from equinox._module._flatten import MISSING
    except ImportError:
        return {}
    return {"equinox.MISSING": MISSING}


def _dumps(value) -> bytes:
    ids = {id(obj): name for name, obj in _sentinels().items()}

    class Pickler(pickle.Pickler):
        def persistent_id(self, obj):
            return ids.get(id(obj))

    buffer = io.BytesIO()
    Pickler(buffer).dump(value)
    return buffer.getvalue()


def _loads(data: bytes):
    sentinels = _sentinels()

    class Unpickler(pickle.Unpickler):
        def persistent_load(self, pid):
            return sentinels[pid]

    return Unpickler(io.BytesIO(data)).load()


def finish() -> None:
    """Wait for every compilation started in the background (each then written to the
    folder): a process may end at once after this."""
    global _executor
    with _lock:
        executor, _executor = _executor, None
    if executor is not None:
        executor.shutdown(wait=True)


def _background() -> concurrent.futures.ThreadPoolExecutor:
    global _executor
    with _lock:
        if _executor is None:
            # Two: statics' program and the run's compile side by side, each on about a
            # core and a half of XLA's threads, while the caller traces the next.
            _executor = concurrent.futures.ThreadPoolExecutor(max_workers=2, thread_name_prefix="jaxcable-compile")
        return _executor


def _is_array(leaf) -> bool:
    return isinstance(leaf, (jax.Array, np.ndarray, np.generic, jax.ShapeDtypeStruct))


def _weak(leaf) -> bool:
    return bool(getattr(leaf, "weak_type", False))


def _abstract(leaf) -> jax.ShapeDtypeStruct:
    return jax.ShapeDtypeStruct(np.shape(leaf), leaf.dtype, weak_type=_weak(leaf))


@functools.cache
def _environment() -> bytes:
    """What every key depends on besides the function and its arguments (see the
    module's notes), computed once per process."""
    package = Path(__file__).parent
    source = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        source.update(str(path.relative_to(package)).encode())
        source.update(path.read_bytes())
    versions = []
    for name in _LIBRARIES:
        try:
            versions.append((name, importlib.metadata.version(name)))
        except importlib.metadata.PackageNotFoundError:
            versions.append((name, None))
    device = jax.devices()[0]
    parts = (
        source.hexdigest(),
        versions,
        device.platform,
        device.device_kind,
        platform.machine(),
        _cpu_flags(),
    )
    return _encode(parts)


def _cpu_flags() -> str:
    """The CPU's instruction-set flags where the system lists them (Linux)."""
    try:
        with open("/proc/cpuinfo") as file:
            for line in file:
                if line.startswith(("flags", "Features")):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


# A run's blocks call their programs with arguments of one structure a hundred times,
# each with dozens of arrays: their part of the key is kept, not encoded anew each call.
@functools.lru_cache(maxsize=1024)
def _array_key(shape: tuple, dtype, weak: bool) -> bytes:
    """An array argument's part of a program's key: its shape, dtype and weak type."""
    return _encode(("array", shape, str(np.dtype(dtype)), weak))


def _describe_tree(tree) -> tuple:
    """The pytree structure: each node's type and static data, and its children."""
    node = tree.node_data()
    if node is None:
        return ("leaf",)
    kind, data = node
    return (_describe(kind), _describe(data), tuple(_describe_tree(child) for child in tree.children()))


_ATOMS = (type(None), bool, int, str, bytes)


def _describe(value, depth: int = 0):
    """A value that pins `value` down exactly, of builtin types only; `_Uncacheable` for
    what it cannot (an object of unknown kind, a closure)."""
    if depth > 50:
        raise _Uncacheable
    inner = functools.partial(_describe, depth=depth + 1)
    if isinstance(value, _ATOMS):
        return (type(value).__name__, value)
    if isinstance(value, float):
        return ("float", value.hex())
    if isinstance(value, complex):
        return ("complex", value.real.hex(), value.imag.hex())
    if isinstance(value, enum.Enum):
        return ("enum", _describe(type(value)), value.name)
    if isinstance(value, (np.ndarray, np.generic)):
        value = np.asarray(value)
        if value.dtype == object:
            raise _Uncacheable
        return ("ndarray", str(value.dtype), value.shape, value.tobytes())
    if isinstance(value, jax.Array):  # a concrete array held as static data
        return _describe(np.asarray(value), depth + 1)
    if isinstance(value, (tuple, list)):
        return (type(value).__name__, tuple(inner(v) for v in value))
    if isinstance(value, dict):
        return ("dict", tuple(sorted((repr(k), inner(v)) for k, v in value.items())))
    if isinstance(value, (frozenset, set)):
        return ("set", tuple(sorted(repr(inner(v)) for v in value)))
    if isinstance(value, type):
        return ("type", value.__module__, value.__qualname__)
    if isinstance(value, functools.partial):
        return ("partial", inner(value.func), inner(value.args), inner(value.keywords))
    if isinstance(value, (types.FunctionType, types.BuiltinFunctionType, types.MethodType)):
        if isinstance(value, types.MethodType):
            return ("method", inner(value.__self__), value.__func__.__qualname__)
        # A function known by its name (a module's global, decorated or not) is fixed
        # by its module's code; a lambda or a local closure may capture anything.
        if _by_name(value) is not value:
            raise _Uncacheable
        return ("function", value.__module__, value.__qualname__)
    key = getattr(value, "__program_key__", None)
    if key is not None:
        return ("keyed", _describe(type(value)), inner(key()))
    if dataclasses.is_dataclass(value) or isinstance(value, eqx.Module):
        return (
            "object",
            _describe(type(value)),
            tuple((f.name, inner(getattr(value, f.name, None))) for f in dataclasses.fields(value)),
        )
    if not getattr(value, "__dict__", True) and not any(getattr(c, "__slots__", ()) for c in type(value).__mro__):
        return ("object", _describe(type(value)))  # a stateless sentinel, such as equinox's MISSING
    raise _Uncacheable


def _by_name(function):
    """The object that `function`'s module and qualified name lead to, or `None`."""
    found = sys.modules.get(getattr(function, "__module__", None) or "")
    for part in getattr(function, "__qualname__", "<").split("."):
        found = getattr(found, part, None)
    return found


def _encode(value) -> bytes:
    """`value` (builtin types only, from `_describe`) as bytes, the same in every
    process: `repr` of tuples, strings, numbers and bytes is deterministic."""
    return repr(value).encode()

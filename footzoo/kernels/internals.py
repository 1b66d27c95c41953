"""Every use of numba's private API in footzoo, in one module.

Tested with numba 0.61.2 (with NumPy 2.2: the kernels', filters' and stream's tests) and 0.68.1 (the
whole suite); ``setup.cfg`` pins ``numba>=0.61,<0.69`` and CI installs the newest release in that
range. A numba release outside it may move one of the names below: this is the one file to read and
adapt. The rest of footzoo uses numba's public API only (``numba.njit``,
``numba.types``, ``numba.extending.overload`` and ``intrinsic``), through :mod:`footzoo.kernels`.

What footzoo takes from numba's internals, and why:

``numba.core.caching.FunctionCache``, ``IndexDataCacheFile`` (:class:`KernelCache`)
    numba's on-disk cache of a kernel, extended to load machine code shipped in a wheel
    (:data:`SHIPPED`) and to key a kernel by the content of every footzoo module it may inline
    (numba keys it by its own file's time stamp only: an edited helper in another module would
    leave stale machine code).
``numba.core.cgutils``, ``numba.np.arrayobj.make_array``,
``numba.core.ir_utils.alias_func_extensions`` (:data:`unowned`)
    An array view whose owner is null: passing it to a function costs no reference counting; numba's
    alias analysis is told that the view aliases its array (else its dead-code elimination may drop
    writes through the view, as it does after inlining an overload).
``numba.core.types.function_type.WrapperAddressProtocol``, ``numba.experimental.function_type._get_wrapper_address``
    (:func:`fixed_address`) A compiled function as a first-class value whose address is looked up once.
``Dispatcher.overloads[...].entry_point``, ``Dispatcher.typeof_pyval`` (:class:`DirectCall`)
    A kernel called straight into its machine code, its arguments typed only when they change;
    tuples of first-class functions are typed here without numba's experimental-feature warning.
``targetoptions["_nrt"] = False`` (:func:`compile_options`)
    A measurement function, or a kernel's loop (``njit(refcounts=False)``: the Kalman filter's forward
    loop), compiled without reference counting when it allocates nothing: numba otherwise calls its
    runtime to count a reference each time the loop takes an array out of a named tuple (about twenty
    calls per sample in the forward loop, each a call through a pointer).
``numba.core.registry.CPUDispatcher`` (:func:`is_dispatcher`)
    Telling a numba dispatcher from any other callable.
``sys.unraisablehook`` (:func:`capture_faults`)
    An exception raised in a function called through its address cannot unwind the caller; numba
    reports it as unraisable. It is collected here and raised by the engine as the plug-in's fault.
``NumbaExperimentalFeatureWarning`` (:func:`quiet`)
    numba warns "First-class function type feature is experimental" whenever it types a tuple of
    function values (stable for functions with an explicit signature, as footzoo's): footzoo types
    those tuples itself (:func:`typeof`) and silences the warning around its own compilations,
    never through the global warnings filter.
"""

from __future__ import annotations

import ast
import contextlib
import hashlib
import inspect
import os
import sys
import threading
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numba import types
from numba.core import cgutils, ir_utils
from numba.core.caching import FunctionCache, IndexDataCacheFile
from numba.core.errors import NumbaExperimentalFeatureWarning
from numba.core.registry import CPUDispatcher
from numba.core.types.function_type import WrapperAddressProtocol
from numba.experimental.function_type import _get_wrapper_address
from numba.extending import intrinsic
from numba.np.arrayobj import make_array

PACKAGE = Path(__file__).resolve().parents[1]  # the footzoo package
#: where the shipped machine code is read from (and written to by ``footzoo compile --ship``)
SHIPPED = Path(os.environ.get("FOOTZOO_SHIPPED_KERNELS") or PACKAGE / "_compiled")

_state = {"shipping": False, "warned": False}
_stamps: dict[Path, str] = {}
_compile_lock = threading.RLock()


# --------------------------------------------------------------------------- warnings
@contextlib.contextmanager
def quiet() -> Iterator[None]:
    """numba's experimental-feature warning silenced while footzoo compiles or types a kernel.

    Under a lock: ``warnings.catch_warnings`` saves and restores the process's filters, which two
    threads must not do at once (numba compiles under its own global lock anyway).
    """
    with _compile_lock, warnings.catch_warnings():
        warnings.simplefilter("ignore", NumbaExperimentalFeatureWarning)
        yield


# --------------------------------------------------------------------------- the kernel cache
def ship(directory: str | os.PathLike) -> None:
    """Write every kernel compiled from now on into ``directory`` (the folder a wheel ships), not numba's cache.

    Kernels are compiled afresh (numba's cache is not read), so the folder receives all that a run uses.
    """
    global SHIPPED
    SHIPPED = Path(directory).resolve()
    _state["shipping"] = True


def _warn_once(message: str) -> None:
    if not _state.get("warned"):
        _state["warned"] = True
        warnings.warn(message, RuntimeWarning, stacklevel=2)


def _footzoo_imports(path: Path) -> set[Path]:
    """The footzoo modules ``path`` imports (top-level and inside functions), as files."""
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except (OSError, SyntaxError, ValueError):
        return set()
    package = path.parent.relative_to(PACKAGE.parent).parts  # ("footzoo", "filters")
    found: set[Path] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = list(package[: len(package) - node.level + 1]) if node.level else []
            parts = base + (node.module.split(".") if node.module else [])
            names = [parts + [alias.name] for alias in node.names] + [parts]
        elif isinstance(node, ast.Import):
            names = [alias.name.split(".") for alias in node.names]
        else:
            continue
        for dotted in names:
            if not dotted or dotted[0] != "footzoo":
                continue
            target = PACKAGE.parent.joinpath(*dotted)
            for candidate in (target.with_suffix(".py"), target / "__init__.py"):
                if candidate.is_file():
                    found.add(candidate.resolve())
    return found


def _content_stamp(path: Path) -> str:
    """A SHA-256 of ``path`` and of every footzoo module it imports, directly or not (their code may be inlined)."""
    if path not in _stamps:
        seen, todo = {path}, [path]
        while todo:
            for dep in _footzoo_imports(todo.pop()):
                if dep not in seen:
                    seen.add(dep)
                    todo.append(dep)
        digest = hashlib.sha256()
        for p in sorted(seen):
            digest.update(str(p.relative_to(PACKAGE)).encode())
            digest.update(p.read_bytes())
        _stamps[path] = digest.hexdigest()
    return _stamps[path]


class KernelCache(FunctionCache):
    """numba's cache of one footzoo kernel, keyed by its modules' content, falling back on shipped machine code.

    ``identity``: for a kernel that wraps a function given at run time (a closure over it, as the
    measurement functions' calling convention is: :mod:`footzoo.kernels.functions`), a text naming that
    function and the content of its source. numba keys a closure's code by its captured values
    pickled, which for a compiled function differ in every process (it would never be found again);
    the identity stands in for them.
    """

    def __init__(self, py_func: Callable[..., Any], source: Path, identity: str | None = None):
        super().__init__(py_func)
        self._source = source
        self._identity = identity
        self._shipped_root: Path | None = None  # the folder the files below were looked up in
        self._shipped_files: list[IndexDataCacheFile] = []

    def _index_key(self, sig: Any, codegen: Any) -> Any:
        signature, magic, (code, captured) = super()._index_key(sig, codegen)
        if self._identity is not None:
            captured = hashlib.sha256(self._identity.encode()).hexdigest()
        return signature, magic, (code, captured, _content_stamp(self._source))

    @property
    def _shipped(self) -> list[IndexDataCacheFile]:
        """The shipped index and data files of this kernel, in the folder :data:`SHIPPED` names now and then
        in each of its parts (while shipping: the folder being written only)."""
        if self._shipped_root != SHIPPED:
            inside = self._source.parent.relative_to(PACKAGE)
            roots = [SHIPPED] if _state["shipping"] else [SHIPPED, *sorted(SHIPPED.glob("part-*"))]
            self._shipped_root = SHIPPED
            self._shipped_files = [
                IndexDataCacheFile(cache_path=str(root / inside), filename_base=self._impl.filename_base,
                                   source_stamp=_content_stamp(self._source)) for root in roots]
        return self._shipped_files

    def _load_overload(self, sig: Any, target_context: Any) -> Any:
        if not self._enabled:
            return None
        data = None if _state["shipping"] else super()._load_overload(sig, target_context)
        if data is None:
            try:
                key = self._index_key(sig, target_context.codegen())
                shipped = next((code for part in self._shipped if (code := part.load(key)) is not None), None)
                if shipped is not None:
                    data = self._impl.rebuild(target_context, shipped)
            except Exception as err:  # a damaged or foreign file: compile instead, and say so once
                _warn_once(f"footzoo: the shipped machine code of {self._name} could not be loaded "
                           f"({type(err).__name__}: {err}); compiling it instead. Reinstall footzoo, or set "
                           "FOOTZOO_SHIPPED_KERNELS to an empty folder to silence this")
        return data

    def _save_overload(self, sig: Any, data: Any) -> None:
        if not _state["shipping"]:
            super()._save_overload(sig, data)
            return
        if not self._enabled or not self._impl.check_cachable(data):
            return
        os.makedirs(SHIPPED / self._source.parent.relative_to(PACKAGE), exist_ok=True)
        writing = self._shipped[0]  # while shipping, the one folder being written
        writing.save(self._index_key(sig, data.codegen), self._impl.reduce(data))


def attach(dispatcher: Any, identity: str | None = None) -> Any:
    """Give a dispatcher of a footzoo kernel the :class:`KernelCache`; others keep numba's cache unchanged.

    Call before the dispatcher compiles (a dispatcher made with an explicit signature compiles at once:
    make it without one and call :func:`compile_with`). ``identity``: see :class:`KernelCache`.
    """
    try:
        source = Path(inspect.getfile(dispatcher.py_func)).resolve()
    except (TypeError, OSError):
        return dispatcher
    if source.suffix == ".py" and PACKAGE in source.parents:
        dispatcher._cache = KernelCache(dispatcher.py_func, source, identity)
    return dispatcher


def compile_with(dispatcher: Any, signature: Any, identity: str | None = None) -> Any:
    """Compile ``dispatcher`` (made with ``cache=True``, no signature) for ``signature`` only, as numba's
    ``njit(signature)`` does, reading and writing the kernel cache (``identity``: see :class:`KernelCache`)."""
    attach(dispatcher, identity)
    with quiet():
        dispatcher.compile(signature)
    dispatcher.disable_compile()
    return dispatcher


def compile_options(refcounting: bool) -> dict[str, Any]:
    """numba's target options for a function compiled with or without reference counting (``_nrt``)."""
    return {} if refcounting else {"_nrt": False}


def counts_references(dispatcher: Any) -> bool:
    """Whether a compiled function counts references (it was not compiled with ``compile_options(False)``)."""
    return dispatcher.targetoptions.get("_nrt") is not False


def is_dispatcher(fn: Any) -> bool:
    """Whether ``fn`` is a numba CPU dispatcher (a function compiled with ``numba.njit``)."""
    return isinstance(fn, CPUDispatcher)


# --------------------------------------------------------------------------- views without an owner
@intrinsic
def unowned(typingctx, a):
    """A view of array ``a`` without an owner: numba counts no references for it.

    Only for arrays that outlive every use of the view: a loop's arguments (a local array is freed
    after its last use, which may be the call of this function), handed to functions which return
    no array.
    """

    def codegen(context, builder, sig, args):
        ary = make_array(sig.args[0])(context, builder, value=args[0])
        ary.meminfo = cgutils.get_null_value(ary.meminfo.type)
        ary.parent = cgutils.get_null_value(ary.parent.type)
        return ary._getvalue()

    return a(a), codegen


def _aliases_its_argument(lhs: str, args: list, alias_map: dict, arg_aliases: set) -> None:
    ir_utils._add_alias(lhs, args[0].name, alias_map, arg_aliases)


ir_utils.alias_func_extensions[("unowned", __name__)] = _aliases_its_argument


# --------------------------------------------------------------------------- functions as values
class FixedAddress(WrapperAddressProtocol):
    """A dispatcher compiled for one signature, seen by numba through its address (looked up once)."""

    def __init__(self, dispatcher: Any):
        self.dispatcher = dispatcher
        self._sig = dispatcher.nopython_signatures[0]
        self._address = _get_wrapper_address(dispatcher, self._sig)

    def __wrapper_address__(self) -> int:
        return self._address

    def signature(self) -> Any:
        return self._sig

    def __call__(self, *args: Any) -> Any:
        return self.dispatcher(*args)


_ADDRESSES: dict[int, FixedAddress] = {}


def fixed_address(fn: Any) -> Any:
    """A compiled function (one signature) as a first-class function value with a fixed address.

    numba types a dispatcher passed as an argument, and looks up its machine-code address, at
    every call of the compiled loop (about 0.2 ms each); the value returned carries the signature
    and the address, looked up once. Anything else (plain Python functions) passes through.
    """
    if not is_dispatcher(fn) or len(fn.signatures) != 1:
        return fn
    cached = _ADDRESSES.get(id(fn))
    if cached is None or cached.dispatcher is not fn:
        cached = _ADDRESSES[id(fn)] = FixedAddress(fn)
    return cached


def typeof(value: Any, dispatcher: Any) -> Any:
    """numba's type of an argument; a tuple of first-class functions typed without numba's unification.

    numba types a tuple element by element and unifies function types (warning that they are
    experimental); footzoo's function values carry their signature (:class:`FixedAddress`), so a
    tuple of them with one signature is a ``UniTuple`` of that function type. A ``NamedTuple`` is
    typed from its fields' types, as numba types it.
    """
    if isinstance(value, tuple):
        inner = [typeof(v, dispatcher) for v in value]
        if type(value) is not tuple:  # a NamedTuple: numba types it without unifying
            return types.BaseTuple.from_types(inner, type(value))
        if not inner:
            return types.Tuple(())
        if all(t == inner[0] for t in inner):
            return types.UniTuple(inner[0], len(inner))
        return types.Tuple(inner)
    if isinstance(value, FixedAddress):
        return types.FunctionType(value.signature())
    return dispatcher.typeof_pyval(value)


#: The array flags numba's type of an array depends on (C and F contiguity, writeable, aligned: NPY_ARRAY_*).
_TYPE_FLAGS = 0x0001 | 0x0002 | 0x0400 | 0x0100


class DirectCall:
    """``kernel(*args)`` straight into the machine code compiled for the arguments' types.

    numba's dispatcher types every argument of every call to choose the machine code; for the
    error-state loop's tuple of first-class functions (the corrections' measurement functions)
    that takes about 0.25 ms per call. Here each call's arguments get a cheap key made of what
    numba's type of them depends on (:meth:`key`: an array's dtype, dimensions, contiguity and
    flags; a Python scalar's class; a tuple's class and its elements' keys; any other object
    itself). While the key is the previous call's, the machine code found for it is called through
    its entry point; a new key is typed (:func:`typeof`) and looked up, and a signature not
    compiled yet is compiled (or loaded from the cache) first: every call runs the code the
    dispatcher would have chosen. The previous call's arguments are kept (their keys hold objects
    by identity): make one per run or per engine, not one per process.
    """

    def __init__(self, dispatcher: Any):
        self.dispatcher = dispatcher
        self._args: tuple = ()  # the previous call's arguments, alive while their key is compared
        self._key: tuple | None = None
        self._types: tuple = ()  # numba's types of the previous call's arguments
        self._entry: Any = None  # the machine code compiled for them

    def __call__(self, *args: Any) -> Any:
        key = self.key(args)
        if self._entry is None or key != self._key:
            self._types = tuple(typeof(a, self.dispatcher) for a in args)
            self._entry = self.entry(self._types)
        self._args, self._key = args, key
        return self._entry(*args)

    def entry(self, signature: tuple) -> Any:
        """The machine code for the argument types ``signature``, compiled (or loaded) now if needed."""
        compiled = self.dispatcher.overloads.get(signature)
        if compiled is None:
            with quiet():
                self.dispatcher.compile(signature)
            compiled = self.dispatcher.overloads[signature]
        return compiled.entry_point

    @classmethod
    def key(cls, value: Any) -> Any:
        """What numba's type of ``value`` is made of, cheap to compute and to compare."""
        if type(value) is np.ndarray:
            return value.dtype, value.ndim, value.flags.num & _TYPE_FLAGS
        if isinstance(value, tuple):
            return type(value), tuple([cls.key(v) for v in value])
        if type(value) in (int, float, bool) or value is None:
            return type(value)
        return type(value), id(value)


# --------------------------------------------------------------------------- faults in compiled functions
_capture = threading.local()
_hook_lock = threading.Lock()
_hook_state: dict[str, Any] = {"depth": 0, "previous": sys.unraisablehook}


def _hook(unraisable: Any) -> None:
    """footzoo's ``sys.unraisablehook``: keeps compiled code's ignored exceptions in a capturing thread."""
    caught = getattr(_capture, "caught", None)
    if caught is not None and "CPUContext" in repr(unraisable.object):
        caught.append(unraisable.exc_value)
        return
    _hook_state["previous"](unraisable)


@contextlib.contextmanager
def capture_faults() -> Iterator[list[BaseException]]:
    """Collect the exceptions raised (and ignored) in compiled functions called through their address.

    Yields the list they are appended to, in this thread; other threads and other unraisable
    exceptions are not affected. The hook is installed while any thread captures (again if something
    else replaced it meanwhile, as test runners do) and the previous one is restored after the last.
    """
    with _hook_lock:
        if sys.unraisablehook is not _hook:
            _hook_state["previous"] = sys.unraisablehook
            sys.unraisablehook = _hook
        _hook_state["depth"] += 1
    outer = getattr(_capture, "caught", None)
    _capture.caught = []
    try:
        yield _capture.caught
    finally:
        _capture.caught = outer
        with _hook_lock:
            _hook_state["depth"] -= 1
            if _hook_state["depth"] == 0 and sys.unraisablehook is _hook:
                sys.unraisablehook = _hook_state["previous"]

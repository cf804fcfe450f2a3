"""The private lower layer of `mjcffi.batch.Batch`: one mjBatch, called as mjbatch.h is.

`mjcffi.batch.Batch(model, nsim)._b` is one of these, in the place of the
official `mujoco.batch.Batch._b`, with its methods, arguments and results.
It owns the mjBatch and guards every call into it; `mjcffi.batch` adds the
public conveniences on top (broadcasting, masks, typed views, named slices).

It converts nothing.  Simulation ids are None (all) or an int32 array; the
other arrays have their exact dtype, their full shape and C order, and the
outputs are writable.  Anything else is a TypeError (a list, another dtype, a
strided array) or a ValueError (a shape, an index out of range, a record
buffer of the wrong size), raised before MuJoCo sees a pointer, since a copy
made here would take the results away from the caller.  The calls return the
number of simulations that failed, as mjb_* do: `status()` and `error(i)` say
which and why.
"""

import operator
import os
import weakref

import numpy as np

from .._support import modelcheck as _modelcheck
from .._support import callbacks as _callbacks
from .._support import contract as _contract
from .._support import official as _official
from .._generated.constants import mjNGROUP
from .._generated.enums import mjtEq, mjtState, mjtWarning
from .._support.errors import check, raise_pending, taken_error, with_note
from .._support.library import ffi, lib
from .._support.views import DTYPES, view
from ..data import MjData
from ..model import MjModel

_NUM = DTYPES["mjtNum"]
_INT = DTYPES["int"]
_BYTE = np.dtype(np.uint8)
_INT_MAX = 2**31 - 1
_USER = int(mjtState.mjSTATE_USER)
_INTEGRATION = int(mjtState.mjSTATE_INTEGRATION)

# MjData fields held in the state rows, by their mjtState component
STATE_FIELDS = {
    "time": mjtState.mjSTATE_TIME,
    "qpos": mjtState.mjSTATE_QPOS,
    "qvel": mjtState.mjSTATE_QVEL,
    "act": mjtState.mjSTATE_ACT,
    "history": mjtState.mjSTATE_HISTORY,
    "qacc_warmstart": mjtState.mjSTATE_WARMSTART,
    "ctrl": mjtState.mjSTATE_CTRL,
    "qfrc_applied": mjtState.mjSTATE_QFRC_APPLIED,
    "xfrc_applied": mjtState.mjSTATE_XFRC_APPLIED,
    "eq_active": mjtState.mjSTATE_EQ_ACTIVE,
    "mocap_pos": mjtState.mjSTATE_MOCAP_POS,
    "mocap_quat": mjtState.mjSTATE_MOCAP_QUAT,
    "userdata": mjtState.mjSTATE_USERDATA,
    "plugin_state": mjtState.mjSTATE_PLUGIN,
    "plastic": mjtState.mjSTATE_PLASTIC,
}

_APPLY_SIGNATURE = "mjfBatchFunc"


class Batch:
    """`nsim` simulations of a copy of `model` on `nthread` threads: one mjBatch.

    The mjBatch is freed (mjb_deleteBatch) when this object and every view
    of its storage are gone.
    """

    def __init__(self, model, nsim, nthread=0, persistent=False):
        if not isinstance(model, MjModel):
            if _official.is_official(model):
                raise _official.not_accepted("model", "MjModel", model)
            raise TypeError(f"model must be an MjModel, not {type(model).__name__}")
        nsim = integer(nsim, "nsim")
        nthread = integer(nthread, "nthread")
        if nsim <= 0:
            raise with_note(ValueError("nsim must be positive"), f"got {nsim}")
        if nsim > _INT_MAX:
            raise ValueError(f"nsim must fit an int (at most {_INT_MAX}), got {nsim}")
        if not -_INT_MAX <= nthread <= _INT_MAX:
            raise ValueError(f"nthread must fit an int (0 or less: one per CPU), got {nthread}")
        check_callbacks()      # mj_makeData may already run the physics
        self.model = model
        self._ptr = _make(model._ptr, nsim, nthread, bool(persistent))
        self.nsim = nsim
        self.nthread = lib.mjb_nthread(self._ptr)
        if self.nthread > 1:
            _threaded.add(self)     # a fork leaves its threads behind: see _after_fork
        self.nstate = lib.mjb_nstate(self._ptr)
        self.persistent = bool(lib.mjb_persistent(self._ptr))
        self._template = None       # an MjData of the model: the shapes of its fields
        self._models = None         # set_models: the caller models and their pointers
        self._checked = {}          # expanded CHECKED_FIELDS: name -> their (nsim, n) rows

    def __repr__(self):
        return f"<mjcffi.batch._batch.Batch nsim={self.nsim} nthread={self.nthread}>"

    # ------------------------------------------------------------ storage

    def state(self):
        """The (nsim, nstate) mjtNum state rows, a writable view."""
        return view(lib.mjb_state(self._ptr), _NUM, (self.nsim, self.nstate), self._ptr)

    def warning(self):
        """The (nsim, mjNWARNING, 2) int warning counters (number, last info), a view."""
        pointer = ffi.cast("int *", lib.mjb_warning(self._ptr))
        return view(pointer, _INT, (self.nsim, mjtWarning.mjNWARNING, 2), self._ptr)

    def status(self):
        """The (nsim,) int status of each simulation's last call (0: no error), read-only."""
        out = view(ffi.cast("int *", lib.mjb_status(self._ptr)), _INT, (self.nsim,), self._ptr)
        out.flags.writeable = False
        return out

    def error(self, sim):
        """The message of the error simulation `sim` raised in its last call, or ''."""
        sim = integer(sim, "sim")
        if not 0 <= sim < self.nsim:
            raise IndexError(f"sim must be in [0, {self.nsim}), got {sim}")
        return ffi.string(lib.mjb_error(self._ptr, sim)).decode("utf-8", "replace")

    def state_component(self, component):
        """(offset, size) of one mjtState component within a state row."""
        size = ffi.new("int *")
        start = lib.mjcffi_guard_mjb_stateComponent(self._ptr, int(component), size)
        raise_pending()
        return start - lib.mjb_state(self._ptr), size[0]

    def output(self, name):
        """The (nsim, nbytes) bytes MjData field `name` is copied into after a call, or None."""
        return self._storage(lib.mjcffi_guard_mjb_output, name)

    def expand(self, name):
        """Give MjModel field `name` per-simulation storage; its (nsim, nbytes) bytes, or None.

        Fields in INDEX_FIELDS are refused (ValueError): their values index
        other arrays.  Those in CHECKED_FIELDS are checked before every call.
        """
        if name in INDEX_FIELDS:
            raise index_field_error(name)
        raw = self._storage(lib.mjcffi_guard_mjb_expand, name)
        if raw is not None and name in CHECKED_FIELDS:
            self._checked[name] = raw.view(_INT)
        return raw

    def expanded(self, name):
        """The (nsim, nbytes) bytes of an expanded MjModel field; None if not expanded."""
        return self._storage(lib.mjcffi_guard_mjb_expanded, name)

    def _storage(self, guard, name):
        if not isinstance(name, str):
            raise TypeError(f"a field name must be a str, not {type(name).__name__}")
        size, elemsize = ffi.new("int *"), ffi.new("int *")
        pointer = guard(self._ptr, name.encode(), size, elemsize)
        raise_pending()
        if pointer == ffi.NULL:
            return None
        shape = (self.nsim, size[0] * elemsize[0])
        return view(ffi.cast("char *", pointer), _BYTE, shape, self._ptr)

    def data_template(self):
        """An MjData of the model, for the shapes and dtypes of its fields."""
        if self._template is None:
            self._template = MjData(self.model)
        return self._template

    # ------------------------------------------------------------ the calls

    def step(self, ids=None, nstep=1, stage=0):
        """mjb_step: `nstep` mj_step calls, then the forward stages up to `stage`."""
        # the hot path of a batch loop: kept to the bare checks
        if ids is None:
            pointer, count = _NULL, 0
        else:
            pointer, count = self._selection(ids)
            if count < 0:
                return 0
        if _contract.python_callbacks:
            check_callbacks()
        if self._checked:
            self.check_expanded()
        try:
            if _contract.python_callbacks:
                failed = _call(_guard_step, self._ptr, pointer, count, nstep, stage)
            else:
                failed = _guard_step(self._ptr, pointer, count, nstep, stage)
        except (TypeError, OverflowError):
            raise _int_error(("nstep", nstep), ("stage", stage)) from None
        message = _take_error()          # raise_pending(), inlined: the hot path
        if message != _NULL:
            raise taken_error(message)
        if _contract.pending:          # a Python mju_user_warning, on the batch's threads
            _contract.raise_stashed()
        return failed

    def forward(self, ids=None, stage=3):
        """mjb_forward: the forward stages up to `stage` (mjtStage)."""
        pointer, count = self._selection(ids)
        if count < 0:
            return 0
        stage = c_int(stage, "stage")
        check_callbacks()
        self.check_expanded()
        return _finish(_call(lib.mjcffi_guard_mjb_forward, self._ptr, pointer, count, stage))

    def reset(self, ids=None, keyframe=None, stage=3):
        """mjb_reset to the defaults, or to `keyframe` ((n,) int32, -1: defaults)."""
        pointer, count = self._selection(ids)
        if count < 0:
            return 0
        key = _NULL
        if keyframe is not None:
            _shape(_typed(keyframe, _INT, "keyframe"), (self._count(ids),), "keyframe")
            key = ffi.from_buffer("int[]", keyframe)
        stage = c_int(stage, "stage")
        check_callbacks()
        self.check_expanded()
        return _finish(_call(lib.mjcffi_guard_mjb_reset, self._ptr, pointer, count, key, stage))

    def set_const(self, ids=None):
        """mjb_setConst: mj_setConst on each selected simulation's model."""
        pointer, count = self._selection(ids)
        if count < 0:
            return 0
        check_callbacks()
        self.check_expanded()
        return _finish(_call(lib.mjcffi_guard_mjb_setConst, self._ptr, pointer, count))

    def rollout(self, ids, nstep, control, control_spec, records):
        """mjb_rollout: `nstep` substeps, each record's buffer filled after each.

        `control` is None or (n, nstep, ncontrol) mjtNum; `records` a sequence
        of (field, spec, buffer) tuples, an MjData field name (spec unused) or
        None and an mjtState spec, and a writable C-contiguous array of the
        record's dtype holding n * nstep of its rows.
        """
        pointer, count = self._selection(ids)
        n = self._count(ids)
        nstep = integer(nstep, "nstep")
        if not 0 < nstep <= _INT_MAX:
            raise with_note(ValueError("nstep must be positive"), f"got {nstep}")
        control_spec = integer(control_spec, "control_spec")
        if control_spec < 0 or control_spec & ~_USER:
            raise ValueError(f"control_spec must be a subset of mjSTATE_USER, got {control_spec}")
        control_pointer = _NULL
        if control is not None:
            ncontrol = lib.mj_stateSize(self.model._ptr, control_spec)
            _shape(_typed(control, _NUM, "control"), (n, nstep, ncontrol), "control")
            control_pointer = ffi.from_buffer("mjtNum[]", control)
        if not isinstance(records, (list, tuple)):
            raise TypeError(f"records must be a list of (field, spec, buffer) tuples, "
                            f"not {type(records).__name__}")
        array = ffi.new("mjBatchRecord[]", max(len(records), 1))
        keep = []          # the field names and buffers MuJoCo points into
        for k, record in enumerate(records):
            keep += self._record(array[k], record, n, nstep)
        if count < 0:
            return 0
        check_callbacks()
        self.check_expanded()
        return _finish(_call(lib.mjcffi_guard_mjb_rollout, self._ptr, pointer, count, nstep,
                             control_pointer, control_spec, array, len(records)))

    def _record(self, entry, record, n, nstep):
        """Fill the mjBatchRecord `entry` from a checked record; return what it points to."""
        if not isinstance(record, tuple):
            raise TypeError(f"a record must be a (field, spec, buffer) tuple, not "
                            f"{type(record).__name__}")
        if len(record) != 3:
            raise ValueError("a record is (field, spec, buffer)")
        field, spec, buf = record
        if field is not None:
            if not isinstance(field, str):
                raise TypeError(f"a record field must be a str or None, not "
                                f"{type(field).__name__}")
            if field not in RECORD_FIELDS:
                raise ValueError(f"unknown field {field}")
            template = data_template(self.data_template(), field)
            shape, dtype, label = template.shape, template.dtype, repr(field)
            name = ffi.new("char[]", field.encode())
            entry.field, entry.spec = name, 0
        else:
            spec = integer(spec, "a record spec")
            if spec < 0 or spec & ~_INTEGRATION:
                raise ValueError(f"invalid state spec {spec}")
            shape = (lib.mj_stateSize(self.model._ptr, spec),)
            dtype, label, name = _NUM, f"state spec {spec}", None
            entry.spec = spec
        if not isinstance(buf, np.ndarray):
            raise ValueError("record buffers must be arrays")
        if not buf.flags.writeable or not buf.flags.c_contiguous:
            raise ValueError("record buffers must be writable and C-contiguous")
        if buf.dtype != dtype or buf.size != n * nstep * int(np.prod(shape)):
            size = " x ".join(str(s) for s in (n, nstep, *shape))
            raise ValueError(f"the record buffer for {label} must hold {size} {dtype}, "
                             f"got {buf.shape} {buf.dtype}")
        # MuJoCo wants a buffer even for an empty record
        entry.buf = ffi.from_buffer(buf if buf.size else _SPARE, require_writable=True)
        return [name, entry.buf]

    def jac(self, ids, body, point, jacp, jacr):
        """mj_jac of `point` ((n, 3)) on `body` ((n,) int32) into jacp and jacr ((n, 3, nv)).

        Per simulation, from its state, after mj_kinematics and mj_comPos;
        jacp and jacr may be None.
        """
        pointer, count = self._selection(ids, checked=True)
        n, nv = self._count(ids), self.model.nv
        _shape(_typed(body, _INT, "body"), (n,), "body")
        _in_range(body, 0, self.model.nbody, "body")
        _shape(_typed(point, _NUM, "point"), (n, 3), "point")
        outputs = []
        for name, out in (("jacp", jacp), ("jacr", jacr)):
            if out is None:        # mj_jac may skip it, but a row of the task may not
                out = np.empty((n, 3, nv), _NUM)
            _shape(_typed(out, _NUM, name, writable=True), (n, 3, nv), name)
            outputs.append(out)
        if count < 0 or n == 0:
            return 0
        arg = ffi.new("mjcffi_batch_jac_arg *")
        # the cdata below keep their arrays alive until mjb_apply returns
        rows = self._rows(ids)
        body_ = ffi.from_buffer("int[]", body)
        point_ = ffi.from_buffer("mjtNum[]", point)
        jacp_ = ffi.from_buffer("mjtNum[]", outputs[0])
        jacr_ = ffi.from_buffer("mjtNum[]", outputs[1])
        arg.rows, arg.nv, arg.body, arg.point, arg.jacp, arg.jacr = \
            rows, nv, body_, point_, jacp_, jacr_
        return self._apply(pointer, count, _BATCH_JAC, arg)

    def ray(self, ids, pnt, vec, geomgroup, flg_static, bodyexclude, dist, geomid, normal):
        """mj_ray of each simulation's (nray, 3) rays `pnt`, `vec`, into dist and geomid.

        pnt and vec are (n, nray, 3) mjtNum, bodyexclude, dist and geomid
        (n, nray) of int32, mjtNum and int32, normal None or (n, nray, 3);
        geomgroup is None or (mjNGROUP,) uint8.
        """
        pointer, count = self._selection(ids, checked=True)
        n = self._count(ids)
        _typed(pnt, _NUM, "pnt")
        if pnt.ndim != 3 or pnt.shape[0] != n or pnt.shape[2] != 3:
            raise ValueError(f"pnt must have shape (n, nray, 3), got {pnt.shape}")
        nray = pnt.shape[1]
        _shape(_typed(vec, _NUM, "vec"), pnt.shape, "vec")
        if geomgroup is not None:
            _shape(_typed(geomgroup, _BYTE, "geomgroup"), (mjNGROUP,), "geomgroup")
        _shape(_typed(bodyexclude, _INT, "bodyexclude"), (n, nray), "bodyexclude")
        _shape(_typed(dist, _NUM, "dist", writable=True), (n, nray), "dist")
        _shape(_typed(geomid, _INT, "geomid", writable=True), (n, nray), "geomid")
        if normal is not None:
            _shape(_typed(normal, _NUM, "normal", writable=True), (n, nray, 3), "normal")
        if count < 0 or n == 0 or nray == 0:
            return 0
        arg = ffi.new("mjcffi_batch_ray_arg *")
        # the cdata below keep their arrays alive until mjb_apply returns
        rows = self._rows(ids)
        pnt_ = ffi.from_buffer("mjtNum[]", pnt)
        vec_ = ffi.from_buffer("mjtNum[]", vec)
        group_ = _NULL if geomgroup is None else ffi.from_buffer("mjtByte[]", geomgroup)
        exclude_ = ffi.from_buffer("int[]", bodyexclude)
        dist_ = ffi.from_buffer("mjtNum[]", dist)
        geomid_ = ffi.from_buffer("int[]", geomid)
        normal_ = _NULL if normal is None else ffi.from_buffer("mjtNum[]", normal)
        arg.rows, arg.nray, arg.pnt, arg.vec = rows, nray, pnt_, vec_
        arg.geomgroup, arg.flg_static, arg.bodyexclude = group_, bool(flg_static), exclude_
        arg.dist, arg.geomid, arg.normal = dist_, geomid_, normal_
        return self._apply(pointer, count, _BATCH_RAY, arg)

    def _apply(self, pointer, count, func, arg):
        """mjb_apply of the C task `func`: on the batch's threads, without the GIL."""
        check_callbacks()
        self.check_expanded()
        return _finish(_call(lib.mjcffi_guard_mjb_apply, self._ptr, pointer, count, func, arg, 0))

    # ------------------------------------------------- models and whole data

    def get_model(self, sim, model):
        """mjb_getModel: simulation `sim`'s model into the MjModel `model`."""
        sim = self._sim(sim)
        if not isinstance(model, MjModel):
            if _official.is_official(model):
                raise _official.not_accepted("model", "MjModel", model)
            raise TypeError(f"model must be an MjModel, not {type(model).__name__}")
        self.check_expanded()
        check(lib.mjcffi_guard_mjb_getModel(self._ptr, sim, model._ptr))

    def get_data(self, sim, data):
        """mjb_getData: simulation `sim`'s state (persistent: its mjData) into `data`."""
        sim = self._sim(sim)
        if not isinstance(data, MjData):
            raise TypeError(f"data must be an MjData, not {type(data).__name__}")
        check(lib.mjcffi_guard_mjb_getData(self._ptr, sim, data._ptr))

    def set_models(self, models):
        """mjb_setModels: run simulation i on models[i] (one MjModel: on it; None: own model).

        The models are kept alive here for as long as MuJoCo reads them.
        """
        if models is None:
            array = _NULL
        else:
            each = [models] * self.nsim if isinstance(models, MjModel) else list(models)
            if len(each) != self.nsim:
                raise with_note(ValueError(f"set_models needs a model per simulation, got "
                                           f"{len(each)} for {self.nsim}"),
                                f"give one MjModel for every simulation, or {self.nsim}, one "
                                "per simulation")
            for k, m in enumerate(each):
                if not isinstance(m, MjModel):
                    if _official.is_official(m):
                        raise _official.not_accepted(f"models[{k}]", "MjModel", m)
                    raise TypeError(f"models[{k}] must be an MjModel, not {type(m).__name__}")
            array = ffi.new("mjModel *[]", [m._ptr for m in each])
        check(lib.mjcffi_guard_mjb_setModels(self._ptr, array))
        # only once MuJoCo holds the new pointers may the old ones go
        self._models = None if models is None else (models, array)

    def check_expanded(self):
        """ValueError if an expanded CHECKED_FIELDS value would let MuJoCo index out of range."""
        for name, rows in self._checked.items():
            CHECKED_FIELDS[name](self.model, name, rows)

    # ------------------------------------------------------------ arguments

    def _selection(self, ids, checked=False):
        """(pointer, count) of int32 `ids` for a call; count -1: an empty selection.

        MuJoCo checks that ids are sorted, unique and in range; `checked` also
        checks the range here, for the tasks that index their rows by id.
        """
        if ids is None:
            return _NULL, 0
        _typed(ids, _INT, "ids")
        if not ids.size:
            return _NULL, -1
        if checked:
            _in_range(ids, 0, self.nsim, "simulation ids")
        return ffi.from_buffer("int[]", ids), ids.size

    def _count(self, ids):
        return self.nsim if ids is None else ids.size

    def _rows(self, ids):
        """Simulation index -> its row in the call's arrays, as int[]; NULL for all."""
        if ids is None:
            return _NULL
        rows = np.zeros(self.nsim, np.int32)
        rows[ids.ravel()] = np.arange(ids.size, dtype=np.int32)
        return ffi.from_buffer("int[]", rows)

    def _sim(self, sim):
        sim = integer(sim, "sim")
        if not 0 <= sim < self.nsim:
            raise IndexError(f"sim must be in [0, {self.nsim}), got {sim}")
        return sim


# ------------------------------------------------------------ fork

# fork() copies the calling thread alone: in a child, a Batch made before the fork has its
# simulations but not MuJoCo's threads, which a call would wait for forever (the official
# Batch hangs there), and which mjb_deleteBatch would wait to join.  Its calls on the
# threads are refused instead; its storage stays readable.
_threaded: weakref.WeakSet = weakref.WeakSet()      # every Batch with threads of its own


def _refused_after_fork(name):
    def refuse(self, *args, **kwargs):
        raise with_note(RuntimeError(f"Batch.{name}: this Batch (nthread={self.nthread}) was "
                                     "made before os.fork(), and its threads did not follow "
                                     "into this child process, so the call would wait "
                                     "forever"),
                        "make a new Batch in the child (its state, bound arrays and "
                        "get_data() can still be read here); a Batch with nthread=1 runs "
                        "on the calling thread and works in a child")
    refuse.__name__ = name
    return refuse


class _ForkedBatch(Batch):
    """A Batch with threads, in a child forked after it was made: the calls that run on
    its threads are refused (see _threaded)."""

    step = _refused_after_fork("step")
    forward = _refused_after_fork("forward")
    reset = _refused_after_fork("reset")
    set_const = _refused_after_fork("set_const")
    rollout = _refused_after_fork("rollout")
    _apply = _refused_after_fork("jac/ray")


def _after_fork():
    for b in list(_threaded):
        ffi.gc(b._ptr, None)         # never join threads that live in the parent
        b.__class__ = _ForkedBatch
    _threaded.clear()


os.register_at_fork(after_in_child=_after_fork)


# ------------------------------------------------------------ mjb_apply tasks

# the native tasks of jac() and ray(), in mjcffi/_c/batchfuncs.c
_BATCH_JAC = ffi.cast(_APPLY_SIGNATURE, ffi.addressof(lib, "mjcffi_batch_jac"))
_BATCH_RAY = ffi.cast(_APPLY_SIGNATURE, ffi.addressof(lib, "mjcffi_batch_ray"))


# ------------------------------------------------------------------ helpers

# mjcffi's callback slots: a Python callable installed in one would run on the
# batch's threads with borrowed wrappers and no simulation to blame, as the
# official Batch refuses it too.
_SLOTS = _callbacks.PHYSICS_SLOTS

_SPARE = np.zeros(1)      # the buffer of empty records
_NULL = ffi.NULL
_guard_step = lib.mjcffi_guard_mjb_step
_take_error = lib.mjcffi_take_error


def check_callbacks():
    """ValueError if a Python callable is installed as a physics callback."""
    for slot in _SLOTS:
        if slot.fn is not None and getattr(lib, slot.name) == slot.trampoline:
            raise ValueError(f"{slot.name} is a Python function; a batch accepts only C "
                             "callbacks (a cffi or ctypes function pointer)")


def _make(model_ptr, nsim, nthread, persistent):
    """mjb_makeBatch, owned by the returned gc cdata; ValueError with MuJoCo's reason."""
    config = ffi.new("mjBatchConfig *")
    lib.mjb_defaultConfig(config)
    config.nthread = nthread
    config.persistent = persistent
    error = ffi.new("char[]", 1024)
    pointer = lib.mjcffi_guard_mjb_makeBatch(model_ptr, nsim, config, error, len(error))
    raise_pending()
    if pointer == ffi.NULL:
        raise ValueError(ffi.string(error).decode("utf-8", "replace")
                         or "mjb_makeBatch could not make the batch")
    return ffi.gc(pointer, lib.mjb_deleteBatch)


def _call(guard, *args):
    """A guarded mjb_* call that may run callbacks on the batch's threads: while it
    runs, their exceptions are this thread's (see mjcffi/_support/callbacks.py)."""
    if not _contract.python_callbacks:
        return guard(*args)
    claim = _contract.scope()
    try:
        return guard(*args)
    finally:
        _contract.unscope(claim)


def _finish(failed):
    """A call's count of failed simulations, or FatalError for arguments MuJoCo
    rejected, or the exception of a Python callback (mju_user_warning) it ran."""
    try:
        raise_pending()
    finally:
        if _contract.pending:
            _contract.raise_stashed()
    return failed


def c_int(value, name):
    """`value` as an int that fits a C int, or TypeError / ValueError naming it."""
    value = integer(value, name)
    if not -_INT_MAX - 1 <= value <= _INT_MAX:
        raise ValueError(f"{name} must fit a C int, got {value}")
    return value


def _int_error(*named):
    """The error for (name, value) arguments that cffi refused as C ints."""
    for name, value in named:
        c_int(value, name)
    return TypeError(f"{', '.join(name for name, _ in named)}: a C int is needed")


def integer(value, name):
    """`value` as an int, or TypeError naming the argument."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be an int, not bool")
    try:
        return operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an int, not {type(value).__name__}") from None


def _typed(value, dtype, name, writable=False):
    """`value` itself, if it is a C-contiguous `dtype` array (writable if asked); else TypeError.

    Nothing is converted: a converted copy would not be the caller's memory.
    """
    if (isinstance(value, np.ndarray) and value.dtype == dtype and value.flags.c_contiguous
            and (value.flags.writeable or not writable)):
        return value
    if not isinstance(value, np.ndarray):
        got = type(value).__name__
    elif value.dtype != dtype:
        got = f"an array of {value.dtype}"
    elif not value.flags.c_contiguous:
        got = "an array that is not C-contiguous"
    else:
        got = "a read-only array"
    kind = "writable C-contiguous" if writable else "C-contiguous"
    raise TypeError(f"{name} must be a {kind} {dtype} array, got {got} (the private "
                    "binding converts nothing)")


def _shape(value, shape, name):
    if value.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {value.shape}")
    return value


def _in_range(value, lo, hi, name):
    """ValueError unless every entry of the int array `value` is in [lo, hi)."""
    bad = value[(value < lo) | (value >= hi)]
    if bad.size:
        raise ValueError(f"{name} must be in [{lo}, {hi}), got {bad.flat[0]}")


def data_template(data, name):
    """MjData field `name` as an array (an int count as a 0-d int32), else None."""
    value = getattr(data, name, None)
    if isinstance(value, np.ndarray):
        return value
    if isinstance(value, int) and not isinstance(value, bool):
        return np.zeros((), np.int32)
    return None


def _field_tables():
    """The names mjb_output, mjb_rollout and mjb_expand accept, as MuJoCo's own tables decide.

    Probed once on an empty model: they know their fields by name, whatever
    the model.
    """
    model = MjModel.from_xml_string("<mujoco/>")
    data = MjData(model)
    probe = _make(model._ptr, 1, 1, False)
    public = [n for n in dir(data) if not n.startswith("_")]
    candidates = [n for n in public if data_template(data, n) is not None]
    data_fields = set(STATE_FIELDS)
    record_fields = set()
    record = ffi.new("mjBatchRecord[1]")
    for name in candidates:
        raw = name.encode()
        if name not in STATE_FIELDS and \
                lib.mjcffi_guard_mjb_output(probe, raw, ffi.NULL, ffi.NULL) != ffi.NULL:
            data_fields.add(name)
        raise_pending()
        buf = np.zeros(max(data_template(data, name).nbytes, 8), np.uint8)
        field = ffi.new("char[]", raw)
        record[0].field, record[0].spec, record[0].buf = field, 0, ffi.from_buffer(buf)
        lib.mjcffi_guard_mjb_rollout(probe, ffi.NULL, 0, 1, ffi.NULL, 0, record, 1)
        if lib.mjcffi_take_error() == ffi.NULL:     # an unknown field is an mju_error
            record_fields.add(name)
    names = [n for n in dir(model) if not n.startswith("_")
             and isinstance(getattr(model, n, None), np.ndarray)]
    names += ["opt." + n for n in dir(model.opt) if not n.startswith("_")
              and not callable(getattr(model.opt, n))]
    model_fields = set()
    for name in names:
        if lib.mjcffi_guard_mjb_expand(probe, name.encode(), ffi.NULL, ffi.NULL) != ffi.NULL:
            model_fields.add(name)
        raise_pending()
    return frozenset(data_fields), frozenset(record_fields), frozenset(model_fields)


# ------------------------------------------------------------ index fields
#
# An mjModel field whose values MuJoCo uses as ids, addresses, counts or types
# of other arrays cannot differ between simulations: one simulation's value
# would make MuJoCo index out of range of arrays that all share one layout
# (a body_parentid past nbody, a jnt_type that makes a hinge's one qpos a free
# joint's seven).  mjb_expand accepts them; expand() refuses them, less those
# checked per simulation (CHECKED_FIELDS).  The model validator classifies them
# from the headers' metadata (mjcffi/_support/modelcheck/fields.py).


def index_field_error(name):
    return with_note(ValueError(f"{name} holds ids, addresses, counts or types of other "
                                "arrays: it cannot differ between simulations"),
                     "a per-simulation value would let MuJoCo index out of range of arrays "
                     "every simulation shares; give the simulations models of their own "
                     "(set_models) to change the structure")


# Expandable fields whose values are checked before each call.

_CONDIM = np.array([1, 3, 4, 6], np.int32)
_BODY_BASED = np.array([mjtEq.mjEQ_CONNECT, mjtEq.mjEQ_WELD], np.int32)


def _check_condim(model, name, rows):
    bad = ~np.isin(rows, _CONDIM)
    if bad.any():
        sim, k = np.argwhere(bad)[0]
        raise ValueError(f"{name}[{k}] of simulation {sim} is {rows[sim, k]}: a contact "
                         "dimensionality is 1, 3, 4 or 6")


def _check_eq_type(model, name, rows):
    """A constraint keeps its objects' kind: its own type, connect <-> weld (bodies or
    sites), or a type MuJoCo itself rejects (mj_step then fails that simulation)."""
    own = np.asarray(model.eq_type)[None, :]
    unknown = (rows < 0) | (rows > max(mjtEq))
    body = np.isin(rows, _BODY_BASED) & np.isin(own, _BODY_BASED)
    bad = ~((rows == own) | unknown | body)
    if bad.any():
        sim, k = np.argwhere(bad)[0]
        raise with_note(ValueError(f"eq_type[{k}] of simulation {sim} is {rows[sim, k]}: "
                                   f"equality {k} is of type {own[0, k]} in the model, and "
                                   "its objects would be read as another kind's ids"),
                        "a connect may become a weld and back; other types must stay the "
                        "model's")


CHECKED_FIELDS = {"geom_condim": _check_condim, "pair_dim": _check_condim,
                  "flex_condim": _check_condim, "eq_type": _check_eq_type}


# MjData fields bind() accepts, MjData fields rollout() records by name, and
# MjModel fields expand() accepts: those mjb_expand accepts, less INDEX_FIELDS
DATA_FIELDS, RECORD_FIELDS, _EXPANDABLE = _field_tables()
INDEX_FIELDS = (_EXPANDABLE & _modelcheck.INDEX_FIELDS) - frozenset(CHECKED_FIELDS)
MODEL_FIELDS = _EXPANDABLE - INDEX_FIELDS

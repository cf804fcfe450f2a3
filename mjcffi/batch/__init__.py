"""Many simulations of one model on MuJoCo's own thread pool: the batch API
of mjbatch.h (mjb_*), with the public face of the official `mujoco.batch`.

    from mjcffi import batch

    b = batch.Batch(model, nsim=1024, nthread=8)
    qpos, ctrl, xpos = b.bind('qpos'), b.bind('ctrl'), b.bind('xpos')
    for _ in range(1000):
        ctrl[:] = policy(qpos, xpos)
        b.step()

A simulation is one row of `b.state`, its integration state.  A call loads
each selected row into an mjData, runs, copies the *bound* derived fields out
and saves the row back, on `nthread` threads including the caller's (cffi
releases the GIL around the call).  Results are bit-identical to a loop over
one MjData per simulation, at any thread count.

- `bind(name)` is a live (nsim, ...) array over an MjData field: a writable
  view of the rows for state fields (qpos, ctrl, mocap_pos, ...), a read-only
  copy-out for derived ones (xpos, sensordata, the counts ncon, nefc, ...),
  refreshed after every call.  Fields are also attributes: `b.xpos` binds
  xpos, and `b.ctrl = u` writes every simulation's controls.
- `expand(name)` gives an MjModel field (or 'opt.<name>' of MjOption) a value
  per simulation; `expanded(name)` reads one without expanding it;
  `set_const()` reruns mj_setConst per simulation.  Fields of ids, addresses,
  counts and types (INDEX_FIELDS: body_parentid, jnt_qposadr, geom_type, ...)
  cannot be expanded, since a per-simulation value would make MuJoCo index
  out of range; contact dimensionalities and eq_type are checked before each
  call (ValueError).
- `joint(name)`, `body(name)`, `sensor(name)`, ... slice those arrays per
  object, with the attributes of MjData's and MjModel's named access:
  `b.joint('hinge').qpos` is (nsim, 1), `b.body('pole').mass = masses`
  writes per-simulation masses.
- `step`, `forward`, `reset`, `rollout`, `jac` and `ray` run on the
  simulations `ids` (sorted unique ints, or a boolean mask), or on all.
- `get_model(i)` and `get_data(i)` materialize one simulation as new MjModel
  and MjData objects; `set_models(models)` runs the simulations on models of
  the caller's.

If MuJoCo raises an error in some simulations, the call raises
SimulationError listing them; they keep the state they had before the call
and the others run to completion.  `b.status` and `b.error(i)` describe each
simulation's last call.  Invalid arguments raise ValueError (TypeError for a
wrong type, IndexError for a simulation index out of range), or
mjcffi.FatalError where MuJoCo's own checks reject them (a bad `stage` or
`nstep`).

Every array here is a zero-copy view of storage the batch owns, and keeps the
batch alive: a view stays valid after the Batch is dropped or closed.  The
mjBatch is freed (mjb_deleteBatch) when its last view and the Batch are gone.

`jac` and `ray` run their per-simulation work as C functions under
mjb_apply (mjcffi/_c/batchfuncs.c), on the batch's threads without the GIL;
an error inside them shows in `status` and `error()` like any other call's.

Each call goes through `b._b` (mjcffi/batch/_batch.py), the lower layer that owns
the mjBatch, as the official Batch's `_b` does: it takes ids and arrays in
their final dtypes and shapes, converts nothing, and checks what keeps C safe.

By default an mjData serves many simulations, so only the fields a call
computes are meaningful; `persistent=True` keeps one mjData per simulation
(and is required for models with sleep or IPC enabled).  Physics callbacks
(`mjcb_*`) must be C functions: with a Python callable installed through
`mjcffi.set_mjcb_*`, the batch's calls raise ValueError.
"""

import copy
import difflib

import numpy as np
from numpy.lib.stride_tricks import as_strided

from . import _batch
from ._batch import DATA_FIELDS, INDEX_FIELDS, MODEL_FIELDS, RECORD_FIELDS
from ._batch import STATE_FIELDS as _STATE_FIELDS
from ._batch import data_template as _template
from ._batch import integer as _integer
from .._generated.enums import mjtStage, mjtState
from .._support.errors import with_note
from .._support.library import lib
from .._support.views import DTYPES
from ..data import MjData
from ..model import MjModel

__all__ = ["Batch", "SimulationError", "DATA_FIELDS", "MODEL_FIELDS"]

_NUM = DTYPES["mjtNum"]
_INT = DTYPES["int"]
_INT_MAX = 2**31 - 1

# the Batch method -> mjcffi's name category, and whether MjData has a side
_NAMED = {
    "actuator": ("actuator", True), "body": ("body", True), "camera": ("cam", True),
    "geom": ("geom", True), "joint": ("jnt", True), "light": ("light", True),
    "sensor": ("sensor", True), "site": ("site", True), "tendon": ("tendon", True),
    "equality": ("eq", False), "keyframe": ("key", False), "material": ("mat", False),
    "numeric": ("numeric", False), "pair": ("pair", False),
}

# what holds the mjBatch: dropped by close()
_HELD = ("_b", "state", "warning", "status")


class SimulationError(RuntimeError):
    """MuJoCo raised an error in some simulations of a call.

    `ids` holds those simulations, sorted.  They kept the state they had
    before the call, and the others ran to completion; `Batch.error(i)` has
    each one's message.
    """

    def __init__(self, ids, message, ncall=None):
        self.ids = np.asarray(ids)
        shown = ", ".join(str(int(i)) for i in self.ids[:5])
        if len(self.ids) > 5:
            shown += ", ..."
        of = "" if ncall is None else f" of {ncall}"
        super().__init__(f"MuJoCo raised an error in {len(self.ids)}{of} simulations "
                         f"({shown}); simulation {int(self.ids[0])}: {message}")


class Batch:
    """`nsim` simulations of a copy of `model`, on `nthread` threads (0: one per CPU).

    With `persistent=True` the batch keeps one mjData per simulation instead
    of one per thread.  A Batch must not be used from several Python threads
    at once: MuJoCo serializes its calls, but each reports failures through
    `status` and `error()`, which the next call overwrites.  A Batch with threads
    (nthread > 1) made before os.fork() cannot step, forward, reset, roll out, jac or
    ray in the child, where its threads are missing (RuntimeError): make a new Batch
    there.
    """

    def __init__(self, model, nsim, nthread=0, persistent=False):
        b = _batch.Batch(model, nsim, nthread, persistent)    # checks the arguments
        set_ = object.__setattr__
        set_(self, "model", model)
        set_(self, "_b", b)                  # the lower layer, as the official's _b
        set_(self, "_nsim", b.nsim)
        set_(self, "_nthread", b.nthread)
        set_(self, "_persistent", b.persistent)
        set_(self, "_nstate", b.nstate)
        set_(self, "_models", None)          # caller models (set_models)
        set_(self, "_nkey", model.nkey)      # keyframes reset() accepts
        set_(self, "_bound", {})             # output name -> (nsim, ...) array
        set_(self, "_expanded", {})          # expanded name -> (nsim, ...) array
        set_(self, "_slices", {})            # (category, id, attr) -> a stable named slice
        set_(self, "state", b.state())
        set_(self, "warning", b.warning())
        set_(self, "status", b.status())

    # ------------------------------------------------------------ attributes

    def __getattr__(self, name):
        # only for names Batch lacks: MjData fields, bound on first use
        state = self.__dict__
        if state.get("_closed") and (name in _HELD or name in DATA_FIELDS):
            raise ValueError("this Batch is closed")
        if name.startswith("_") or "_b" not in state:
            raise AttributeError(f"'Batch' object has no attribute {name!r}")
        if name in DATA_FIELDS:
            value = self.bind(name)
            state[name] = value          # later reads find it without __getattr__
            return value
        raise AttributeError(f"'Batch' object has no attribute {name!r}"
                             + _hint(name, DATA_FIELDS, expand_hint=True))

    def __setattr__(self, name, value):
        if name in DATA_FIELDS:          # write every simulation's value, as on MjData
            if name not in _STATE_FIELDS:
                raise _output_error(name)
            _assign(self.bind(name), value, name)
        else:
            object.__setattr__(self, name, value)

    def __repr__(self):
        if self.__dict__.get("_closed"):
            return "<Batch (closed)>"
        return (f"<Batch nsim={self._nsim} nthread={self._nthread} "
                f"persistent={self._persistent}>")

    @property
    def nsim(self):
        """The number of simulations."""
        return self._nsim

    @property
    def nthread(self):
        """The number of threads the batch runs on, the caller's included."""
        return self._nthread

    @property
    def nstate(self):
        """The length of a state row: mj_stateSize(model, mjSTATE_INTEGRATION)."""
        return self._nstate

    @property
    def persistent(self):
        """Whether the batch keeps one mjData per simulation."""
        return self._persistent

    @property
    def models(self):
        """The caller models of set_models, or None for the batch's model.

        One MjModel if it was set for every simulation, else a tuple with
        simulation i's model at index i.
        """
        models = self._models
        if models is None or isinstance(models, MjModel):
            return models
        return tuple(models)

    @property
    def _data(self):
        """An MjData of the model, for the shapes and dtypes of its fields."""
        return self._b.data_template()

    def close(self):
        """Let go of the batch: later calls raise ValueError.

        The mjBatch, its threads and its storage are freed as soon as no view
        of that storage (a bound, expanded or state array) is left.
        """
        for name in [n for n in self.__dict__ if n in DATA_FIELDS]:
            del self.__dict__[name]
        for name in _HELD:
            self.__dict__.pop(name, None)
        for cache in (self._bound, self._expanded, self._slices):
            cache.clear()
        object.__setattr__(self, "_closed", True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def error(self, sim):
        """The message of the error simulation `sim` raised in its last call, or ''."""
        return self._b.error(sim)

    # ------------------------------------------------------ fields of MjData

    def bind(self, name):
        """A live (nsim, ...) array over MjData field `name`, one of DATA_FIELDS.

        State fields are writable views of the rows, which hold mjtNum, so
        eq_active binds as mjtNum rather than as MjData's bytes.  Other fields
        are outputs, copied out after every call on a simulation, and
        read-only; until the first call they are zero in a batch that is not
        persistent.  The counts (ncon, nefc, ...) bind as (nsim,) ints.
        """
        out = self._bound.get(name)
        if out is not None:
            return out
        component = _STATE_FIELDS.get(name)
        if component is not None:
            rows = self._component(component)
            if name == "time":
                out = rows[:, 0]
            else:
                out = _shaped(rows, (self._nsim, *getattr(self._data, name).shape))
            self._bound[name] = out
            return out
        template = _template(self._data, name) if isinstance(name, str) else None
        raw = None if template is None else self._b.output(name)
        if raw is None:
            raise _not_bindable(self._data, name)
        out = _typed(raw, template, name)
        out.flags.writeable = False      # the next call would overwrite a write
        self._bound[name] = out
        return out

    def _component(self, component):
        """The (nsim, size) view of the rows holding one mjtState component."""
        offset, size = self._b.state_component(component)
        return self.state[:, offset:offset + size]

    # ----------------------------------------------------- fields of MjModel

    def expand(self, name):
        """Give MjModel field `name` per-simulation values; return them, live.

        Array fields are named as in MjModel, MjOption fields 'opt.<name>'
        (one of MODEL_FIELDS).  The (nsim, ...) array starts with the model's
        values, and row i is copied into the model before every call on
        simulation i.  bvh_aabb holds only the bodies' bounding volumes.
        After writing a field that mj_setConst reads (or an MjOption field),
        call set_const() so that the constants derived from it follow.
        """
        out = self._expanded.get(name)
        if out is not None:
            return out
        template = _model_template(self.model, name) if isinstance(name, str) else None
        raw = None
        if template is not None and name in MODEL_FIELDS:
            raw = self._b.expand(name)
        if raw is None:
            raise _not_expandable(self.model, name)
        out = _typed(raw, template, name)
        self._expanded[name] = out
        return out

    def expanded(self, name):
        """The read-only per-simulation values of MjModel field `name`, or None.

        None while every simulation has the model's value; otherwise the
        values expand() or set_const() gave it, without expanding anything.
        """
        if name not in MODEL_FIELDS and name not in INDEX_FIELDS:
            raise _not_expandable(self.model, name)
        raw = self._b.expanded(name)
        if raw is None:
            return None
        out = _typed(raw, _model_template(self.model, name), name)
        out.flags.writeable = False      # set_const() overwrites derived values
        return out

    def set_const(self, ids=None):
        """Run mj_setConst on each selected simulation's model.

        The fields it changes become per-simulation, as with expand().
        """
        ids = _ids(ids, self._nsim)
        self._check(ids, self._b.set_const(ids))

    # ------------------------------------------------------------- the calls

    def step(self, ids=None, nstep=1, stage=0):
        """Advance each simulation by `nstep` calls to mj_step, then compute stages.

        As with mj_step, derived fields describe the state before the last
        substep.  `stage` (mjtStage) computes the forward stages up to it at
        the new state: mjSTAGE_VEL makes position- and velocity-dependent
        fields and sensors current, as mj_step1 does, and costs nothing extra
        in a persistent batch, whose next step continues from it;
        mjSTAGE_ACC runs mj_forward.
        """
        # the hot path of a batch loop: kept to the bare checks
        if ids is not None:
            ids = _ids(ids, self._nsim)
        if self._b.step(ids, nstep, stage):
            self._fail(ids)

    def forward(self, ids=None, stage=mjtStage.mjSTAGE_ACC):
        """Compute the forward stages up to `stage` (mjtStage); by default mj_forward."""
        ids = _ids(ids, self._nsim)
        self._check(ids, self._b.forward(ids, stage))

    def reset(self, ids=None, keyframe=-1, stage=mjtStage.mjSTAGE_ACC):
        """Reset to the model's defaults or to keyframes, then compute stages.

        `keyframe` is one keyframe for every simulation of the call or one
        each, -1 for the defaults.  Writes to the state made before the call
        are discarded.  stage=mjSTAGE_NONE skips the forward pass, for a
        reset followed by writes to the state and forward().
        """
        ids = _ids(ids, self._nsim)
        n = self._nsim if ids is None else ids.size
        key = _int32(keyframe, (n,), -1, self._nkey, "keyframe")
        self._check(ids, self._b.reset(ids, None if (key == -1).all() else key, stage))

    def rollout(self, nstep, control=None, control_spec=mjtState.mjSTATE_CTRL,
                record=("qpos",), ids=None, out=None):
        """Advance each simulation by `nstep` substeps, recording after each.

        Before substep k, the state components in `control_spec` (within
        mjSTATE_USER) are set from `control`, (n, nstep, ncontrol) for the n
        simulations of the call, broadcast; with `control` None the inputs are
        left as they are.  `record` names MjData fields (with MjData's dtypes,
        so eq_active is not mjtNum here) or mjtState specs of state vectors.
        A simulation whose warning counters rise stops stepping, and its
        remaining records repeat its last ones.  `out` maps record items to
        arrays to write into, of the shapes and dtypes returned.

        Returns a dict from each record item to its (n, nstep, ...) array.
        """
        nstep = _integer(nstep, "nstep")
        if not 0 < nstep <= _INT_MAX:
            raise with_note(ValueError("nstep must be positive"), f"got {nstep}")
        ids = _ids(ids, self._nsim)
        n = self._nsim if ids is None else ids.size
        m = self.model._ptr
        control_spec = _integer(control_spec, "control_spec")
        if control_spec & ~int(mjtState.mjSTATE_USER) or control_spec < 0:
            raise ValueError(f"control_spec must be a subset of mjSTATE_USER, got {control_spec}")
        if control is not None:
            shape = (n, nstep, lib.mj_stateSize(m, control_spec))
            control = _broadcast(control, shape, _NUM, "control")
        given = {} if out is None else out
        if not callable(getattr(given, "get", None)):
            raise TypeError(f"out must be a dict from record items to arrays, not "
                            f"{type(out).__name__}")
        result, records = {}, []
        for item in record:
            if isinstance(item, str):
                if item not in RECORD_FIELDS:
                    raise _not_recordable(self._data, item)
                template = _template(self._data, item)
                shape, dtype = (n, nstep, *template.shape), template.dtype
            else:
                spec = _integer(item, "a record spec")
                if spec < 0 or spec & ~int(mjtState.mjSTATE_INTEGRATION):
                    raise ValueError(f"record spec {spec} is not a set of mjtState bits")
                shape, dtype = (n, nstep, lib.mj_stateSize(m, spec)), _NUM
            buf = given.get(item)
            if buf is None:
                buf = np.empty(shape, dtype)
            elif (not isinstance(buf, np.ndarray) or buf.shape != shape or buf.dtype != dtype
                  or not buf.flags.c_contiguous or not buf.flags.writeable):
                raise ValueError(f"out[{item!r}] must be a writable C-contiguous {dtype} array "
                                 f"of shape {shape}")
            records.append((item, 0, buf) if isinstance(item, str) else (None, spec, buf))
            result[item] = buf
        self._check(ids, self._b.rollout(ids, nstep, control, control_spec, records))
        return result

    def jac(self, body, point, ids=None):
        """Translational and rotational Jacobians of a world point on a body.

        Per simulation, from its state: mj_kinematics, mj_comPos, then
        mj_jac.  The state and bound fields are untouched; in a persistent
        batch the simulation's mjData keeps these kinematics.  `body` is one
        body id or one per simulation of the call; `point` (3,) or (n, 3).

        Returns jacp and jacr, (n, 3, nv) each.
        """
        ids = _ids(ids, self._nsim)
        n = self._nsim if ids is None else ids.size
        nv = self.model.nv
        bodies = _int32(body, (n,), 0, self.model.nbody, "body")
        point = _broadcast(point, (n, 3), _NUM, "point")
        jacp, jacr = np.zeros((n, 3, nv), _NUM), np.zeros((n, 3, nv), _NUM)
        self._check(ids, self._b.jac(ids, bodies, point, jacp, jacr))
        return jacp, jacr

    def ray(self, pnt, vec, geomgroup=None, flg_static=True, bodyexclude=-1, ids=None,
            normal=False):
        """Intersect rays with each simulation's geoms, as mj_ray.

        Per simulation, from its state: mj_kinematics (and mj_flex if the
        model has flexes), then mj_ray for each ray.  `pnt` and `vec` are
        broadcast to (n, nray, 3) for the n simulations of the call;
        `bodyexclude` to (n, nray); `geomgroup` is (mjNGROUP,) or None.

        Returns dist and geomid, (n, nray) each, -1 for a miss; with
        `normal`, also the surface normals, (n, nray, 3), zero for a miss.
        """
        ids = _ids(ids, self._nsim)
        n = self._nsim if ids is None else ids.size
        pnt = np.atleast_2d(np.asarray(pnt, _NUM))
        vec = np.atleast_2d(np.asarray(vec, _NUM))
        try:
            nray = np.broadcast_shapes(pnt.shape[:-1], vec.shape[:-1])[-1]
        except ValueError as exc:
            raise with_note(exc, f"pnt {pnt.shape} and vec {vec.shape} hold different numbers "
                            "of rays") from None
        pnt = _broadcast(pnt, (n, nray, 3), _NUM, "pnt")
        vec = _broadcast(vec, (n, nray, 3), _NUM, "vec")
        exclude = _int32(bodyexclude, (n, nray), -1, self.model.nbody, "bodyexclude")
        if geomgroup is not None:
            flags = np.asarray(geomgroup)         # checked: a value past uint8 would wrap
            if flags.dtype.kind == "b":
                flags = flags.astype(np.uint8)
            geomgroup = _int32(flags, flags.shape, 0, 256, "geomgroup").astype(np.uint8)
        # mj_ray writes every entry, -1 for a miss
        dist, geomid = np.zeros((n, nray), _NUM), np.zeros((n, nray), _INT)
        normals = np.zeros((n, nray, 3), _NUM) if normal else None
        self._check(ids, self._b.ray(ids, pnt, vec, geomgroup, flg_static, exclude, dist,
                                     geomid, normals))
        return (dist, geomid) if normals is None else (dist, geomid, normals)

    def _check(self, ids, nfail):
        """After a call on `ids`: SimulationError if `nfail` simulations failed."""
        if nfail:
            self._fail(ids)

    def _fail(self, ids):
        selected = np.arange(self._nsim) if ids is None else ids
        failed = selected[self.status[selected] != 0]
        raise SimulationError(failed, self.error(int(failed[0])), len(selected))

    def _sim(self, sim):
        """`sim` as an index, or IndexError."""
        sim = _integer(sim, "sim")
        if not 0 <= sim < self._nsim:
            raise IndexError(f"sim must be in [0, {self._nsim}), got {sim}")
        return sim

    # ------------------------------------------------ models and whole data

    def get_model(self, sim, model=None):
        """Simulation `sim`'s model, with its per-simulation fields, as an MjModel.

        `model` is an MjModel with the sizes of that model to write into, or
        None for a new copy.  With caller models (set_models) it is a copy of
        simulation sim's model.  The result is the caller's: it shares no
        memory with the batch.
        """
        sim = self._sim(sim)
        if model is None:
            model = copy.copy(self._model_of(sim))
        self._b.get_model(sim, model)
        return model

    def get_data(self, sim, data=None):
        """Simulation `sim`'s state, and in a persistent batch its whole mjData.

        `data` is an MjData of the batch's sizes to write into, or None for a
        new one.  Outside a persistent batch the derived fields are not the
        simulation's: run mj_forward with get_model(sim) to compute them.
        """
        sim = self._sim(sim)
        if data is None:
            data = MjData(self.model)
        self._b.get_data(sim, data)
        return data

    def set_models(self, models):
        """Run simulation i on models[i], a model of the caller's.

        `models` is an MjModel per simulation, one MjModel for all, or None
        for the batch's own model.  Each must give MjData the batch's layout.
        The batch keeps them alive and only reads them: after editing one,
        call set_models again.  Caller models replace per-simulation fields:
        set_models raises if fields are expanded, and expand() and
        set_const() raise while models are set.
        """
        if models is not None and not isinstance(models, MjModel):
            models = list(models)
        self._b.set_models(models)     # checks them, and keeps them alive for MuJoCo
        object.__setattr__(self, "_models", models)
        if models is None:
            nkey = self.model.nkey
        elif isinstance(models, MjModel):
            nkey = models.nkey
        else:
            nkey = max(m.nkey for m in models)
        object.__setattr__(self, "_nkey", nkey)

    def _model_of(self, sim):
        """The model simulation `sim` runs on, but for its per-simulation fields."""
        models = self._models
        if models is None:
            return self.model
        return models if isinstance(models, MjModel) else models[sim]

    # --------------------------------------------------------- named views

    def actuator(self, key):
        """Actuator `key` (name or id): its slices of the bound and expanded fields."""
        return _Named(self, "actuator", key)

    def body(self, key):
        """Body `key` (name or id): its slices of the bound and expanded fields."""
        return _Named(self, "body", key)

    def camera(self, key):
        """Camera `key` (name or id): its slices of the bound and expanded fields."""
        return _Named(self, "camera", key)

    def equality(self, key):
        """Equality `key` (name or id): its slices of the expanded model fields."""
        return _Named(self, "equality", key)

    def geom(self, key):
        """Geom `key` (name or id): its slices of the bound and expanded fields."""
        return _Named(self, "geom", key)

    def joint(self, key):
        """Joint `key` (name or id): its slices of the bound and expanded fields."""
        return _Named(self, "joint", key)

    def keyframe(self, key):
        """Keyframe `key` (name or id): its slices of the expanded model fields."""
        return _Named(self, "keyframe", key)

    def light(self, key):
        """Light `key` (name or id): its slices of the bound and expanded fields."""
        return _Named(self, "light", key)

    def material(self, key):
        """Material `key` (name or id): its slices of the expanded model fields."""
        return _Named(self, "material", key)

    def numeric(self, key):
        """Numeric `key` (name or id): its slices of the expanded model fields."""
        return _Named(self, "numeric", key)

    def pair(self, key):
        """Pair `key` (name or id): its slices of the expanded model fields."""
        return _Named(self, "pair", key)

    def sensor(self, key):
        """Sensor `key` (name or id): its slices of the bound and expanded fields."""
        return _Named(self, "sensor", key)

    def site(self, key):
        """Site `key` (name or id): its slices of the bound and expanded fields."""
        return _Named(self, "site", key)

    def tendon(self, key):
        """Tendon `key` (name or id): its slices of the bound and expanded fields."""
        return _Named(self, "tendon", key)

    def _named_slice(self, named, attr, write):
        """The (nsim, ...) slice of one named attribute (see _Named)."""
        cache_key = (named._category, named.id, attr)
        cached = self._slices.get(cache_key)
        if cached is not None and (not write or cached.flags.writeable):
            return cached
        unheld = False       # an attribute of the accessors, but in no field we hold
        for accessor, is_model in ((named._data_view, False), (named._model_view, True)):
            field = accessor._fields.get(attr) if accessor is not None else None
            if field is None:
                continue
            if field.kind == "dense":     # computed from several fields, not a slice
                unheld = True
                continue
            part = getattr(accessor, attr)
            if not part.size:             # as empty as MjData's and MjModel's views
                out = np.zeros((self._nsim, *part.shape), part.dtype)
                out.flags.writeable = False
                return out
            name = field.name
            if not is_model:
                if name not in DATA_FIELDS:
                    unheld = True
                    continue
                if write and name not in _STATE_FIELDS:
                    raise _output_error(f"{named._label} {attr}")
                out = _cut(self.bind(name), getattr(self._data, name), part)
                self._slices[cache_key] = out
                return out
            if name not in MODEL_FIELDS and name not in INDEX_FIELDS:
                unheld = True
                continue
            if self._models is not None:
                if write:
                    raise ValueError(f"{name} comes from the caller models (set_models): edit "
                                     "them and call set_models again")
                out = np.stack([getattr(getattr(self._model_of(i), named._category)(named.id),
                                        attr) for i in range(self._nsim)])
                out.flags.writeable = False
                return out
            full = getattr(self.model, name)
            if name in self._expanded or (write and not _structural(name, part)):
                out = _cut(self.expand(name), full, part)
                self._slices[cache_key] = out    # expanded storage never moves
                return out
            if _structural(name, part):
                if write:
                    raise ValueError(f"{name} is structural (addresses, counts, ids, types): "
                                     "it cannot differ between simulations")
                return np.broadcast_to(part, (self._nsim, *part.shape))
            rows = self.expanded(name)            # set_const's values, if any
            if rows is None:
                return np.broadcast_to(part, (self._nsim, *part.shape))
            return _cut(rows, full, part)
        if unheld:
            raise AttributeError(f"{named._label} {attr} is not a slice of a field that the "
                                 "batch binds or expands")
        names = set(named._model_view._fields)
        if named._data_view is not None:
            names |= set(named._data_view._fields)
        raise AttributeError(f"{attr} is not a field of a {named._label}"
                             + _did_you_mean(attr, names))


class _Named:
    """One object's slices of the batch's per-simulation fields.

    `b.joint('hinge').qpos` is the part of `b.bind('qpos')` that
    `d.joint('hinge').qpos` is of `d.qpos`; `b.body('pole').mass` the part of
    `b.expand('body_mass')` that `m.body('pole').mass` is of `m.body_mass`.
    Data attributes bind their field; writes are allowed on state fields.
    Model attributes read without expanding: the per-simulation values of a
    field that expand() or set_const() expanded, else the model's value for
    every simulation, read-only.  Assigning one expands the field and writes
    every simulation's value.  Structural model fields (addresses, counts,
    ids, types) are the same in every simulation and cannot be assigned.
    With caller models (set_models), model attributes are read-only copies
    from each simulation's model.
    """

    def __init__(self, batch, method, key):
        category, has_data = _NAMED[method]
        model_view = getattr(batch.model, category)(key)
        data_view = getattr(batch._data, category)(key) if has_data else None
        state = self.__dict__
        state.update(_batch=batch, _category=category, _label=method, _model_view=model_view,
                     _data_view=data_view, id=model_view.id, name=model_view.name)

    def __getattr__(self, attr):
        if attr.startswith("_"):
            raise AttributeError(attr)
        return self._batch._named_slice(self, attr, write=False)

    def __setattr__(self, attr, value):
        """Write `value` to every simulation's slice: b.joint('j').qpos = 0.5."""
        if attr in ("id", "name") or attr.startswith("_"):
            raise AttributeError(f"{attr} is read-only")
        _assign(self._batch._named_slice(self, attr, write=True), value,
                f"{self._label} {attr}")

    def __dir__(self):
        names = set(self._model_view._fields) | {"id", "name"}
        if self._data_view is not None:
            names |= set(self._data_view._fields)
        return sorted(names)

    def __repr__(self):
        return f"<Batch {self._label} {self.name!r} (id {self.id})>"


# -------------------------------------------------------------------- helpers

def _ids(ids, nsim):
    """Checked int32 simulation ids from ints or a boolean mask; None for all.

    Dtype, shape, order, uniqueness and range are checked before narrowing
    to int32, so that no id can wrap or truncate into a valid one.
    """
    if ids is None:
        return None
    ids = np.asarray(ids)
    if ids.dtype == np.bool_:
        if ids.shape != (nsim,):
            raise with_note(ValueError(f"a boolean mask must have shape ({nsim},)"),
                            f"the mask of simulations has shape {ids.shape}")
        return None if ids.all() else np.flatnonzero(ids).astype(np.int32)
    if ids.ndim != 1:
        raise with_note(ValueError("ids must be one-dimensional"), f"got shape {ids.shape}")
    if ids.size == 0:
        return np.zeros(0, np.int32)
    if ids.dtype.kind not in "iu":
        raise ValueError(f"ids must be integers, got {ids.dtype}")
    if ids.size > 1:
        bad = np.flatnonzero(ids[:-1] >= ids[1:])      # compared: unsigned cannot wrap
        if bad.size:
            k = bad[0]
            raise ValueError(f"ids must be sorted and unique, got {ids[k]} before {ids[k + 1]}")
    if ids[0] < 0 or ids[-1] >= nsim:        # sorted: only the ends can be out of range
        raise ValueError(f"ids must be in [0, {nsim}), got {ids[0] if ids[0] < 0 else ids[-1]}")
    return np.ascontiguousarray(ids, dtype=np.int32)


def _int32(value, shape, lo, hi, name):
    """Integers in [lo, hi), broadcast to `shape`, checked before narrowing to int32."""
    value = np.asarray(value)
    if value.dtype.kind not in "iu":
        raise ValueError(f"{name} must be integers, got {value.dtype}")
    bad = value[(value < lo) | (value >= hi)]
    if bad.size:
        raise ValueError(f"{name} must be in [{lo}, {hi}), got {bad.flat[0]}")
    try:
        return np.ascontiguousarray(np.broadcast_to(value, shape), np.int32)
    except ValueError as exc:
        raise with_note(exc, f"{name} must broadcast to shape {shape}, got {value.shape}")


def _broadcast(value, shape, dtype, name):
    """`value` broadcast to `shape` as a C-contiguous array, or ValueError naming it."""
    value = np.asarray(value, dtype)
    try:
        return np.ascontiguousarray(np.broadcast_to(value, shape))
    except ValueError as exc:
        raise with_note(exc, f"{name} must have shape {shape} (or broadcast to it), "
                        f"got {value.shape}")


def _assign(target, value, name):
    """Write `value` into `target`, naming the field on a bad shape."""
    try:
        target[...] = value
    except (ValueError, TypeError) as exc:
        raise with_note(exc, f"cannot assign to {name} of shape {target.shape}")


def _shaped(rows, shape):
    """The (nsim, k) view `rows`, contiguous within a row, viewed as `shape`."""
    inner = []
    stride = rows.itemsize
    for n in reversed(shape[1:]):
        inner.append(stride)
        stride *= n
    return as_strided(rows, shape, (rows.strides[0], *reversed(inner)))


def _typed(raw, template, name):
    """The (nsim, nbytes) bytes `raw` of per-simulation storage as (nsim, *template.shape)."""
    if raw.shape[1] % template.dtype.itemsize:
        raise RuntimeError(f"{name}: MuJoCo stores {raw.shape[1]} bytes per simulation, not a "
                           f"whole number of {template.dtype} elements")
    return _per_simulation(raw.view(template.dtype), template)


def _per_simulation(flat, template):
    """(nsim, n) storage as (nsim, *template.shape).

    bvh_aabb holds a prefix of the model's rows, possibly none, so the row
    count comes from the storage when it differs from the template's.
    """
    nsim, n = flat.shape
    if n == template.size:
        return _shaped(flat, (nsim, *template.shape))
    row = int(np.prod(template.shape[1:]))
    return _shaped(flat, (nsim, n // row, *template.shape[1:]))


def _cut(rows, full, part):
    """The slice of per-simulation `rows` that `part` is of the template array `full`."""
    nsim = rows.shape[0]
    start = (part.ctypes.data - full.ctypes.data) // full.itemsize
    flat = as_strided(rows, (nsim, rows[0].size), (rows.strides[0], rows.itemsize))
    return _shaped(flat[:, start:start + part.size], (nsim, *part.shape))


def _structural(name, part):
    """Whether model field `name` holds addresses, counts, ids or types."""
    return name in INDEX_FIELDS or (part.dtype.kind in "iu"
                                    and name.endswith(("adr", "num", "id", "type"))
                                    and not name.endswith("contype"))


def _model_template(model, name):
    """MjModel field `name` (or 'opt.<name>') as an array of its stored dtype, else None."""
    if name.startswith("opt."):
        value = getattr(model.opt, name[4:], None)
        if value is None or callable(value):
            return None
        value = np.asarray(value)
        # MjOption stores mjtNum and int
        return value if value.dtype.kind == "f" else value.astype(np.int32)
    value = getattr(model, name, None)
    return value if isinstance(value, np.ndarray) else None


def _did_you_mean(name, names):
    close = difflib.get_close_matches(name, sorted(names), n=3)
    return f" (did you mean {', '.join(map(repr, close))}?)" if close else ""


def _hint(name, names, expand_hint=False):
    """Where `name` belongs if it is a model or option field, else close matches."""
    if expand_hint and name in MODEL_FIELDS:
        return f"; {name} is an MjModel field: use expand({name!r})"
    if "opt." + name in MODEL_FIELDS:
        return f"; {name} is an MjOption field: use expand('opt.{name}')"
    return _did_you_mean(name, names)


def _not_bindable(data, name):
    """The error for a name bind() refuses; `data` is a template MjData."""
    if not isinstance(name, str):
        return with_note(TypeError(f"attribute name must be string, not "
                                   f"'{type(name).__name__}'"), "bind() takes a field name")
    if name in MODEL_FIELDS:
        return ValueError(f"{name} is an MjModel field: use expand({name!r})")
    value = getattr(data, name, None)
    if isinstance(value, np.ndarray):
        return ValueError(f"{name} is in the arena, whose size changes from step to step, "
                          "and cannot be bound")
    if isinstance(value, int):
        counts = sorted(n for n in DATA_FIELDS if isinstance(getattr(data, n, None), int))
        return ValueError(f"{name} is not one of the MjData scalars bind() accepts: "
                          f"{', '.join(counts)}")
    return ValueError(f"{name} is not an MjData array field" + _hint(name, DATA_FIELDS))


def _not_recordable(data, name):
    """The error for a record item rollout() refuses: the official message, and ours as a note."""
    if _template(data, name) is None:
        error = _not_bindable(data, name)
    else:
        error = ValueError(f"unknown field {name}")
    if name in _STATE_FIELDS:
        return with_note(error, f"{name} cannot be recorded by name: record the state spec "
                         f"mjtState.{_STATE_FIELDS[name].name}")
    value = getattr(data, name, None)
    if isinstance(value, np.ndarray):
        return with_note(error, f"{name} is in the arena, whose size changes from step to step, "
                         "and cannot be recorded")
    if isinstance(value, int):
        counts = sorted(n for n in RECORD_FIELDS if isinstance(getattr(data, n, None), int))
        return with_note(error, f"the MjData scalars rollout() records: {', '.join(counts)}")
    return error


def _not_expandable(model, name):
    """The error for a name expand() refuses."""
    if not isinstance(name, str):
        return TypeError(f"a field name must be a str, not {type(name).__name__}")
    if name in DATA_FIELDS:
        return ValueError(f"{name} is an MjData field: use bind({name!r})")
    if name in INDEX_FIELDS:
        return _batch.index_field_error(name)
    if isinstance(getattr(model, name, None), np.ndarray):
        return ValueError(f"{name} is asset data, shared by all simulations, and cannot be "
                          "expanded")
    return ValueError(f"{name} is not an expandable MjModel field" + _hint(name, MODEL_FIELDS))


def _output_error(name):
    """The error for a write to an output, which every call overwrites."""
    return ValueError(f"{name} is computed by every call and cannot be written; write state "
                      "fields (qpos, ctrl, ...) or expand model fields")

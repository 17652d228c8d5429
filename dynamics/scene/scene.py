"""`Scene`: a hub and the parts mounted on it, assembled into one `Model`."""
from __future__ import annotations

import math
from types import MappingProxyType

import numpy as np

from .. import cache
from ..model import Model
from ..validate import finite_array
from .assembly import PartLayout, assemble
from .contract import Frame, Part
from .hubs import RigidHub

__all__ = ["Scene", "check_scene"]

HUB = "hub"


@cache.memoize
def _model(scene: "Scene") -> Model:
    return assemble(scene)


class Scene:
    """A vehicle assembled from a hub and parts; ``.model()`` is its `Model`.

    A scene carries exactly the parts it was given: a hub alone is the rigid body (7
    states), each part adds its own states, controls, loads and invariants
    (`dynamics.scene.contract`). Scenes are immutable and compare and hash by value, so
    the model of an equal scene is built once (`dynamics.cache`).

    Parameters
    ----------
    hub : RigidHub
    *parts : Part
        Reaction wheels, CMGs, dampers, panels, loads... in the order their states and
        controls appear. Parts without a ``name`` are named after their kind; several of a
        kind become ``damper``, ``damper_2``, ...; where a state or control name would repeat,
        the later part's names get the same suffix (``s_2``, ``s_dot_2``).
    name : str, optional
        The model's name (default ``"scene"``).

    Raises
    ------
    TypeError
        If ``hub`` is not a `RigidHub` or a part is not a `Part`.
    ValueError
        If two parts are given the same ``name``, or a ``parent`` is not a part of the
        scene, cannot carry parts, or closes a cycle.

    Examples
    --------
    A hub with three reaction wheels and a body torque:

    >>> import numpy as np
    >>> from appdyn.dynamics.scene import ExternalTorque, ReactionWheels, RigidHub, Scene
    >>> scene = Scene(RigidHub([10.0, 12.0, 8.0]), ReactionWheels(np.eye(3), 0.05, u_max=0.1),
    ...               ExternalTorque())
    >>> model = scene.model()
    >>> model.states[7:], model.controls
    (('W1', 'W2', 'W3'), ('tau1', 'tau2', 'tau3', 'L1', 'L2', 'L3'))
    >>> scene.layout["wheels"].states, scene.layout["torque"].controls
    (slice(7, 10, None), slice(3, 6, None))
    >>> scene.state(w=[0.0, 0.0, 0.1], wheels=[10.0, 0.0, 0.0])
    array([ 0. ,  0. ,  0. ,  1. ,  0. ,  0. ,  0.1, 10. ,  0. ,  0. ])
    """

    __slots__ = ("hub", "parts", "name", "_names", "_vars", "_parents", "_order")

    def __init__(self, hub, *parts, name=None):
        if not isinstance(hub, RigidHub):
            raise TypeError(f"`hub` must be a RigidHub, got {type(hub).__name__}")
        for k, part in enumerate(parts):
            if not isinstance(part, Part):
                raise TypeError(f"part {k + 1} must be a scene Part (ReactionWheels, "
                                f"ExternalTorque, ...), got {type(part).__name__}")
        if name is not None and (not isinstance(name, str) or not name.isidentifier()):
            raise ValueError(f"`name` must be an identifier-like str, got {name!r}")
        object.__setattr__(self, "hub", hub)
        object.__setattr__(self, "parts", tuple(parts))
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "_names", _part_names(parts))
        object.__setattr__(self, "_vars", None)
        object.__setattr__(self, "_parents", _part_parents(self.parts, self._names))
        object.__setattr__(self, "_order", _mount_order(self._names, self._parents))

    def __setattr__(self, key, value):
        raise AttributeError("a Scene is immutable; build a new one")

    def __eq__(self, other):
        return (isinstance(other, Scene) and self.hub == other.hub
                and self.parts == other.parts and self.name == other.name)

    def __hash__(self):
        return hash((Scene, self.hub, self.parts, self.name))

    def __reduce__(self):
        return (_rebuild_scene, (self.hub, self.parts, self.name))

    def __repr__(self):
        inner = ", ".join([repr(self.hub)] + [repr(p) for p in self.parts])
        return f"Scene({inner}{'' if self.name is None else f', name={self.name!r}'})"

    def __str__(self):
        hub = "RigidHub" + (" (6-DoF)" if self.hub.translates else "")
        parts = [f"{n} ({type(p).__name__}{'' if at is None else ' on ' + at})"
                 for p, n, at in zip(self.parts, self._names, self._parents)]
        return f"{self.name or 'scene'}: " + " + ".join([hub] + parts)

    # --------------------------------------------------------------- naming
    @property
    def part_names(self) -> tuple:
        """The parts' names, in order."""
        return self._names

    @property
    def parents(self) -> tuple:
        """Each part's parent: the name of the part it sits on, None for the hub."""
        return self._parents

    @property
    def mount_order(self) -> tuple:
        """Part indices with every parent before the parts it carries (else scene order)."""
        return self._order

    def variable_names(self) -> dict:
        """States, controls, units, bounds and each part's local -> scene names."""
        if self._vars is not None:
            return self._vars
        coords, speeds = self.hub.variables()
        hub_states = coords[:4] + speeds[:3] + coords[4:] + speeds[3:]
        states = [v.name for v in hub_states]
        units = {v.name: v.unit for v in hub_states}
        controls, bounds, rest, terminal = [], {}, {}, {}
        for v in hub_states:
            rest[v.name] = v.rest
            terminal[v.name] = v.terminal
        local_all, layout = {}, {}
        # the hub: q, w [, r, v]; its coordinates are q [and r], its speeds w [and v]
        layout[HUB] = PartLayout(slice(0, len(states)), slice(0, 0), slice(0, 4),
                                 slice(4, 7), tuple(states))
        for part, pname in zip(self.parts, self._names):
            pv = part.variables()
            group = list(pv.coords) + list(pv.speeds) + list(pv.controls)
            taken = set(states) | set(controls)
            suffix, k = "", 1
            while any(v.name + suffix in taken for v in group) or len(
                    {v.name for v in group}) < len(group):
                if len({v.name for v in group}) < len(group):
                    raise ValueError(f"part {pname!r} declares a variable name twice")
                k += 1
                suffix = f"_{k}"
            local = {"__coords__": [v.name for v in pv.coords],
                     "__speeds__": [v.name for v in pv.speeds],
                     "__controls__": [v.name for v in pv.controls]}
            s0, c0 = len(states), len(controls)
            for v in group:
                full = v.name + suffix
                local[v.name] = full
                units[full] = v.unit
                if any(math.isfinite(b) for b in v.bounds):
                    bounds[full] = tuple(v.bounds)
            for v in list(pv.coords) + list(pv.speeds):
                states.append(v.name + suffix)
                rest[v.name + suffix] = v.rest
                terminal[v.name + suffix] = v.terminal
            controls += [v.name + suffix for v in pv.controls]
            nc = len(pv.coords)
            layout[pname] = PartLayout(
                slice(s0, len(states)), slice(c0, len(controls)), slice(s0, s0 + nc),
                slice(s0 + nc, len(states)),
                tuple(states[s0:]) + tuple(controls[c0:]))
            local_all[pname] = local
        out = {"states": tuple(states), "controls": tuple(controls), "units": units,
               "bounds": bounds, "rest": rest, "terminal": terminal, "local": local_all,
               "layout": MappingProxyType(layout)}
        object.__setattr__(self, "_vars", out)
        return out

    @property
    def layout(self):
        """Each part's (and ``"hub"``'s) `PartLayout`: its slices of ``x`` and ``u``."""
        return self.variable_names()["layout"]

    @property
    def states(self) -> tuple:
        """The state names, in order."""
        return self.variable_names()["states"]

    @property
    def controls(self) -> tuple:
        """The control names, in order."""
        return self.variable_names()["controls"]

    def part(self, name: str):
        """The part called ``name``."""
        if name not in self._names:
            raise KeyError(f"no part named {name!r}; the parts are {list(self._names)}")
        return self.parts[self._names.index(name)]

    # --------------------------------------------------------------- model
    def model(self) -> Model:
        """The assembled `Model` (built once per equal scene; `dynamics.cache`).

        Returns
        -------
        Model
            States: the hub's (``q1..q4, w1..w3`` [, ``r1..r3, v1..v3``]) then each part's
            coordinates and speeds; controls: each part's; no parameters;
            ``attitude = (0, 4)``; ``layout`` and ``bounds`` from the parts; invariants
            ``energy`` [J] (kinetic plus the parts' potential energy), ``momentum_inertial``
            [N m s] (about the reference point, fixed for an attitude-only hub; about the
            inertial origin with ``mass``), ``momentum_linear`` [N s] (with ``mass``),
            ``quat_norm`` and the parts' own.
        """
        return _model(self)

    def state(self, **blocks) -> np.ndarray:
        """A state vector from named blocks; every block not given at rest.

        Parameters
        ----------
        **blocks : array_like
            ``q`` (4, scalar-last), ``w`` (3, [rad/s]), ``r``, ``v`` (3 each, six-degree-of-
            freedom hub), a part's name (all its states, coordinates then speeds), or any
            single state by name (``W1=...``). At rest, a part's speeds are those relative
            rest implies at the given ``w`` (a spherical damper's core turns with the hub).

        Returns
        -------
        numpy.ndarray, shape (nx,)

        Raises
        ------
        ValueError
            Naming an unknown block or one of the wrong size.
        """
        names = self.variable_names()
        states = names["states"]
        x = np.array([names["rest"][s] for s in states], dtype=float)
        index = {s: i for i, s in enumerate(states)}
        hub_blocks = {"q": (0, 4), "w": (4, 7)}
        if self.hub.translates:
            hub_blocks.update(r=(7, 10), v=(10, 13))
        given_parts = set()
        singles = {}
        for key, value in blocks.items():
            if key in hub_blocks:
                lo, hi = hub_blocks[key]
                x[lo:hi] = finite_array(value, key, (hi - lo,))
            elif key in self._names:
                sl = self.layout[key].states
                n = sl.stop - sl.start
                x[sl] = finite_array(value, key, (n,))
                given_parts.add(key)
            elif key in index:
                singles[key] = float(finite_array(value, key, ()))
            else:
                raise ValueError(f"unknown state block {key!r}; give q, w"
                                 f"{', r, v' if self.hub.translates else ''}, a part name "
                                 f"{list(self._names)} or a state name")
        # parts at rest relative to the hub turning at w
        import casadi as ca
        from ..attitude import dcm_from_quat
        frame = Frame(q=ca.DM(x[0:4]), dcm=ca.DM(dcm_from_quat(x[0:4])), w=ca.DM(x[4:7]),
                      v=ca.DM.zeros(3), r=None, reference=self.hub.reference,
                      mass=self.hub.mass, reference_rate=self.hub.reference_rate)
        for key, val in singles.items():  # before: a part's frame may depend on them
            x[index[key]] = val
        frames = {}
        for i in self._order:
            part, pname, parent = self.parts[i], self._names[i], self._parents[i]
            lay = self.layout[pname]
            on = frame if parent is None else frames[parent]
            if pname not in given_parts and lay.speeds.stop > lay.speeds.start:
                own = _NumericOwn(x[lay.coords], x[lay.speeds])
                x[lay.speeds] = np.asarray(ca.evalf(part.spin_speeds(on, own))).reshape(-1)
                for key in set(singles) & set(self.states[lay.speeds]):
                    x[index[key]] = singles[key]  # a speed given by name wins
            if pname in self._parents:
                frames[pname] = part.body_frame(on, _NumericOwn(x[lay.coords], x[lay.speeds]))
        for key, val in singles.items():
            x[index[key]] = val
        return x


def check_scene(scene, name: str = "scene") -> Scene:
    """``scene`` if it is a `Scene`; a ``TypeError`` naming ``name`` otherwise."""
    if not isinstance(scene, Scene):
        raise TypeError(f"`{name}` must be a dynamics.scene.Scene (Scene(RigidHub(inertia), "
                        f"*parts)), got {type(scene).__name__}")
    return scene


def _rebuild_scene(hub, parts, name) -> Scene:
    """Inverse of `Scene.__reduce__` (pickling, process pools)."""
    return Scene(hub, *parts, name=name)


class _NumericOwn:
    """`PartSymbols` stand-in with numbers, for `Part.spin_speeds` at a numeric state."""

    def __init__(self, coords, speeds):
        import casadi as ca
        self.coords, self.speeds, self.controls = ca.DM(coords), ca.DM(speeds), ca.DM(0, 1)


def _part_parents(parts, names) -> tuple:
    """Each part's parent name (None: the hub), checked (module docstring of the contract)."""
    parents = []
    for part, pname in zip(parts, names):
        parent = getattr(part, "parent", None)
        if parent is None or parent == HUB:
            parents.append(None)
            continue
        if not isinstance(parent, str):
            raise TypeError(f"part {pname!r}: `parent` must be the name of a part (str) or "
                            f"None, got {type(parent).__name__}")
        if not type(part).mountable:
            raise ValueError(f"part {pname!r} ({type(part).__name__}) acts on the whole scene "
                             f"and cannot sit on another part: drop `parent`")
        if parent not in names:
            raise ValueError(f"part {pname!r}: `parent` {parent!r} is not a part of the scene; "
                             f"the parts are {list(names)}")
        host = parts[names.index(parent)]
        if not type(host).carries_parts:
            raise ValueError(f"part {pname!r}: its `parent` {parent!r} "
                             f"({type(host).__name__}) cannot carry parts (a HingedPanel or a BendingMode can)")
        parents.append(parent)
    for pname in names:
        seen, at = {pname}, parents[names.index(pname)]
        while at is not None:
            if at in seen:
                raise ValueError(f"the parents of part {pname!r} form a cycle through "
                                 f"{at!r}; every chain of parents must end at the hub")
            seen.add(at)
            at = parents[names.index(at)]
    return tuple(parents)


def _mount_order(names, parents) -> tuple:
    """Indices of the parts, parents first, else in the scene's order."""
    order, placed = [], set()
    while len(order) < len(names):
        for i, (pname, parent) in enumerate(zip(names, parents)):
            if pname not in placed and (parent is None or parent in placed):
                order.append(i)
                placed.add(pname)
    return tuple(order)


def _part_names(parts) -> tuple:
    names, counts = [], {}
    for part in parts:
        given = getattr(part, "name", None)
        if given is not None:
            if not isinstance(given, str) or not given.isidentifier() or given == HUB:
                raise ValueError(f"a part's `name` must be an identifier other than 'hub', "
                                 f"got {given!r}")
            if given in names:
                raise ValueError(f"two parts are named {given!r}; names must be distinct")
            names.append(given)
            continue
        kind = part.kind
        counts[kind] = counts.get(kind, 0) + 1
        name = kind if counts[kind] == 1 else f"{kind}_{counts[kind]}"
        while name in names:
            counts[kind] += 1
            name = f"{kind}_{counts[kind]}"
        names.append(name)
    return tuple(names)

"""ScenarioBuilder: a scenario written from Python, table by table, as TOML text read by the very
reader the CLI uses (docs/scenario-format.md lists every key). The checks, the error messages
(naming the key, e.g. ``ball[2].radius``, and its allowed range) and the Simulation built are those of
the CLI; builder.toml() is a file `hilldem run` runs to the same bits."""
import json
import math
import numbers

from ._core import Simulation


def _value(v, where):
    """One TOML value: numbers exactly (repr round-trips a float), strings, booleans, lists."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        f = float(v)
        if math.isnan(f):
            return "nan"
        if math.isinf(f):
            return "inf" if f > 0 else "-inf"
        return repr(f)
    if isinstance(v, str):
        return json.dumps(v)
    if hasattr(v, "tolist"):  # numpy arrays and scalars
        return _value(v.tolist(), where)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x, where) for x in v) + "]"
    raise TypeError(f"{where}: cannot write a {type(v).__name__} as a TOML value")


def toml_table(header, keys):
    """The TOML text of one table: header "[simulation]" or "[[ball]]", then `key = value` lines."""
    lines = [header]
    for k, v in keys.items():
        lines.append(f"{k} = {_value(v, header + ' ' + k)}")
    return "\n".join(lines) + "\n"


class ScenarioBuilder:
    """A scenario built in Python. Each method adds the TOML table of its name with the keys given
    (units as in docs/scenario-format.md: SI, e.g. radius [m], density [kg/m^3], young_mod [Pa]);
    build() reads it with the CLI's reader into a hilldem.Simulation."""

    _SINGLE = ("simulation", "output", "snapshots", "checkpoints")

    def __init__(self, title=None):
        """An empty scenario; `title` is its title line."""
        self._single = {}
        self._arrays = []
        if title is not None:
            self._title = title
        else:
            self._title = None

    def _table(self, kind, keys):
        self._arrays.append((kind, dict(keys)))
        return self

    def simulation(self, **keys):
        """[simulation]: gravity [m/s^2], local_damping [-], timestep [s] or "auto", proximity [m], ..."""
        self._single.setdefault("simulation", {}).update(keys)
        return self

    def output(self, **keys):
        """[output]: dir, history_every [steps], history_file."""
        self._single.setdefault("output", {}).update(keys)
        return self

    def snapshots(self, **keys):
        """[snapshots]: VTK snapshots (every [steps], format, ...)."""
        self._single.setdefault("snapshots", {}).update(keys)
        return self

    def checkpoints(self, **keys):
        """[checkpoints]: every [steps], every_seconds [s], keep, ..."""
        self._single.setdefault("checkpoints", {}).update(keys)
        return self

    def material(self, name, **keys):
        """[[material]]: density [kg/m^3], young_mod [Pa], pois_ratio [-]."""
        return self._table("material", {"name": name, **keys})

    def ball(self, id, position, radius, material, **keys):
        """[[ball]]: user id, position [m], radius [m], material name; groups, fix, velocity [m/s], spin [rad/s]."""
        return self._table("ball", {"id": id, "position": position, "radius": radius, "material": material, **keys})

    def balls(self, ids, positions, radii, material, **keys):
        """Many [[ball]] tables: ids (n,), positions (n, 3) [m], radii (n,) [m], one material; other keys apply to all."""
        ids, positions, radii = list(ids), list(positions), list(radii)
        if not (len(ids) == len(positions) == len(radii)):
            raise ValueError(f"balls: ids, positions and radii must have the same length; got {len(ids)}, "
                             f"{len(positions)}, {len(radii)}")
        for i, x, r in zip(ids, positions, radii):
            self.ball(i, x, r, material, **keys)
        return self

    def ball_grid(self, **keys):
        """[[ball_grid]]: first_id, origin [m], counts [nx, ny, nz], spacing [m], radius [m], material."""
        return self._table("ball_grid", keys)

    def packing(self, **keys):
        """[[packing]]: balls from a LAMMPS or xyzr file."""
        return self._table("packing", keys)

    def wall(self, name, type, **keys):
        """[[wall]]: type "plane" (point [m], normal), "facet" (vertices [m]), "cylinder" (center, radius [m], axis, extent) or "box"."""
        return self._table("wall", {"name": name, "type": type, **keys})

    def servo(self, **keys):
        """[[servo]]: a wall servo to a target_stress [Pa]."""
        return self._table("servo", keys)

    def contact_model(self, **keys):
        """[[contact_model]]: an assignment rule (name, between, groups, model "linear"/"hill"/"rrlinear" and its parameters)."""
        return self._table("contact_model", keys)

    def history(self, **keys):
        """[[history]]: a quantity recorded every output.history_every steps."""
        return self._table("history", keys)

    def stage(self, type, **keys):
        """[[stage]]: cycle, solve, translate, rotate, set, set_contacts, set_simulation, make_wet, make_dry, probe, ..."""
        return self._table("stage", {"type": type, **keys})

    def toml(self):
        """The scenario as TOML text (a file `hilldem run` runs)."""
        parts = []
        if self._title is not None:
            parts.append(f"title = {_value(self._title, 'title')}\n")
        for kind in self._SINGLE:
            if kind in self._single:
                parts.append(toml_table(f"[{kind}]", self._single[kind]))
        for kind, keys in self._arrays:
            parts.append(toml_table(f"[[{kind}]]", keys))
        return "\n".join(parts)

    def build(self, name="<ScenarioBuilder>"):
        """The hilldem.Simulation (InputError naming `name` and the key on bad input)."""
        return Simulation._from_text(self.toml(), name)


def add_balls(sim, materials, balls):
    """Append balls to a simulation: materials {name: {density, young_mod, pois_ratio}}, balls a list
    of [[ball]] key dicts (id, position [m], radius [m], material, ...), checked by the scenario
    reader. Returns how many were added. Raises BufferError while numpy views of the simulation's
    ball arrays are alive (the arrays may move in memory): delete them or take copies first."""
    text = "".join(toml_table("[[material]]", {"name": n, **k}) for n, k in materials.items())
    text += "".join(toml_table("[[ball]]", b) for b in balls)
    return sim._add_balls(text, "add_balls")


Simulation.add_balls = add_balls

"""The scene's [solid] table for solid-rigid, read strictly: an unknown key is an error with a
"did you mean", a wrong value names the key and the file. The keys are a subset of solid/'s
(solid/README.md) plus `fixed` and `angular_velocity`; README.md lists them."""
import difflib
import math
import os
import tomllib

from wire import Failure

PROGRAM = "solid-rigid"


class Table:
    """A TOML table that records which keys were read, so that finish() can name the rest."""

    def __init__(self, data, path, file):
        self.data, self.path, self.file, self.asked = data, path, file, set()
        self.effective = {}

    def key(self, k):
        return f"{self.path}.{k}" if self.path else k

    def fail(self, k, what):
        raise Failure(f"{self.key(k)} {what} (in {self.file})")

    def get(self, k, default=None, kind=None):
        self.asked.add(k)
        v = self.data.get(k, default)
        if v is None:
            raise Failure(f"missing key {self.key(k)} (in {self.file})")
        if kind is float:
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                self.fail(k, f"must be a number, got {v!r}")
            v = float(v)
            if not math.isfinite(v):
                self.fail(k, f"must be finite, got {v}")
        elif kind is not None and not isinstance(v, kind) or (kind is int and isinstance(v, bool)):
            self.fail(k, f"must be of type {kind.__name__}, got {v!r}")
        self.effective[k] = v
        return v

    def vec2(self, k, default=None):
        v = self.get(k, default)
        if (not isinstance(v, list) or len(v) != 2
                or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in v)
                or not all(math.isfinite(x) for x in v)):
            self.fail(k, f"must be two finite numbers [x, y], got {v!r}")
        self.effective[k] = [float(x) for x in v]
        return [float(x) for x in v]

    def has(self, k):
        return k in self.data

    def sub(self, k):
        self.asked.add(k)
        v = self.data[k]
        if not isinstance(v, dict):
            self.fail(k, "must be a table")
        t = Table(v, self.key(k), self.file)
        self.effective[k] = t.effective
        return t

    def subs(self, k):
        """An array of tables ([[k]]); [] when absent."""
        self.asked.add(k)
        v = self.data.get(k, [])
        if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
            self.fail(k, "must be an array of tables [[...]]")
        ts = [Table(x, f"{self.key(k)}[{i}]", self.file) for i, x in enumerate(v)]
        self.effective[k] = [t.effective for t in ts]
        return ts

    def finish(self, why=None):
        for k in self.data:
            if k in self.asked:
                continue
            near = difflib.get_close_matches(k, sorted(self.asked), n=1, cutoff=0.6)
            hint = (f"; did you mean '{near[0]}'?" if near else
                    f"; known keys here: {', '.join(sorted(self.asked))}")
            raise Failure(f"unknown key '{self.key(k)}' (in {self.file}){hint}"
                          + (f" ({why})" if why else ""))


class Body:
    pass


def read(path):
    """(raw bytes, settings dict, bodies, the [solid] Table) of the scene file at path."""
    try:
        raw = open(path, "rb").read()
    except OSError as e:
        raise Failure(f"cannot read scene file {path}: {e.strerror}")
    try:
        doc = tomllib.loads(raw.decode())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise Failure(f"TOML syntax error in scene file {path}: {e}")
    s = {"file": path, "dir": os.path.dirname(os.path.abspath(path))}
    stem = os.path.splitext(os.path.basename(path))[0]
    s["name"] = doc.get("scene", {}).get("name", stem)
    s["needs"] = [k in doc for k in ("fluid", "solid", "fiber")]
    s["needs"].append(sum(s["needs"]) >= 2)
    fluid = doc.get("fluid", {})
    s["fluid_density"] = float(fluid.get("density", 0.0)) if isinstance(fluid, dict) else 0.0
    out = doc.get("output", {})
    s["checkpoint_interval"] = out.get("checkpoint_interval", 0) if isinstance(out, dict) else 0
    it = doc.get("coupler", {}).get("iterations", {}) if isinstance(doc.get("coupler"), dict) else {}
    s["iterations_max"] = it.get("max", 1) if isinstance(it, dict) else 1
    if "solid" not in doc:
        return raw, s, [], None
    return raw, s, None, Table(doc["solid"], "solid", path)


def read_solid(t, settings, read_mesh):
    """The [solid] table: the program name, gravity, the bodies with their meshes."""
    program = t.get("program", PROGRAM, str)
    if program != PROGRAM:
        t.fail("program", f'= "{program}": this is the program {PROGRAM}; the scene is for '
                          f'{program}')
    settings["gravity"] = t.vec2("gravity", [0.0, 0.0])
    bodies = []
    for bt in t.subs("body"):
        b = Body()
        b.name = bt.get("name", None, str)
        if any(o.name == b.name for o in bodies):
            bt.fail("name", f'"{b.name}" is used by two bodies')
        kind = bt.get("kind", "rigid", str)
        if kind != "rigid":
            bt.fail("kind", f'= "{kind}": {PROGRAM} moves rigid bodies only (kind = "rigid"); '
                            'elastic bodies are the program solid\'s')
        b.fixed = bt.get("fixed", False, bool)
        b.gravity = bt.get("gravity", True, bool)
        b.velocity = bt.vec2("velocity", [0.0, 0.0])
        b.angular_velocity = bt.get("angular_velocity", 0.0, float)
        b.x, b.tri, b.source = read_mesh(bt, settings["dir"])
        mats = bt.subs("material")
        if b.fixed:
            b.density = math.inf
            if mats:
                bt.fail("material", "is not read for a fixed body (it does not move); remove it")
        else:
            if len(mats) != 1:
                bt.fail("material", f"must be one [[material]] with the body's density, got "
                                    f"{len(mats)}")
            m = mats[0]
            b.density = m.get("density", None, float)
            if not b.density > 0:
                m.fail("density", f"must be > 0, got {b.density:g}: a body of zero mass has no "
                                  "dynamics")
            m.finish(f"{PROGRAM} reads only the density of a rigid body")
        bt.finish()
        bodies.append(b)
    if not bodies:
        t.fail("body", "is missing: solid-rigid needs at least one [[solid.body]]")
    t.finish()
    return bodies


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("inf" if v > 0 else "-inf" if v < 0 else "nan")
    if isinstance(v, int):
        return str(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def effective_toml(t):
    """The [solid] table as read (defaults filled in), TOML, for the effective_scene message."""
    lines = []

    def table(d, path, array):
        lines.append(f"[[{path}]]" if array else f"[{path}]")
        subs = []
        for k, v in d.items():
            if isinstance(v, dict):
                subs.append((k, v, False))
            elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
                subs.extend((k, x, True) for x in v)
            else:
                lines.append(f"{k} = {toml_value(v)}")
        for k, v, arr in subs:
            table(v, f"{path}.{k}", arr)

    table(t.effective, "solid", False)
    return "\n".join(lines) + "\n"

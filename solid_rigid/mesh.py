"""A body's mesh, as solid/ reads it: a Gmsh `.geo` (meshed through the gmsh Python module, with
the same DefineConstant values, size factor and refinements) or `.msh`, or the built-in
structured rectangle (the same nodes and triangles as solid/'s rectangle_mesh). Then the
counter-clockwise check and the surface edges (edges of exactly one triangle, body on the left)."""
import math
import os

import numpy as np

from wire import Failure

MAX_REFINE = 6


def parse_parameters(t, key):
    """ "nx = 140, ny = 8" -> [("nx", 140.0), ("ny", 8.0)] """
    text = t.get(key, None, str)
    out = []
    for item in filter(None, (s.strip() for s in text.split(","))):
        name, eq, value = item.partition("=")
        try:
            out.append((name.strip(), float(value)))
        except ValueError:
            eq = ""
        if not eq or not name.strip():
            t.fail(key, f'must be "name = value, ...", got "{text}"')
    return out


def read_gmsh(path, parameters, size_factor, refine, key):
    if not os.path.isfile(path):
        raise Failure(f"{key}: mesh file '{path}' does not exist")
    ext = os.path.splitext(path)[1]
    if ext not in (".geo", ".msh"):
        raise Failure(f"{key}: mesh file '{path}' is not a Gmsh file (expected a .geo or .msh "
                      "extension)")
    if ext == ".msh" and not open(path, "rb").readline().startswith(b"$MeshFormat"):
        raise Failure(f"{key}: mesh file '{path}' is not a Gmsh mesh (no $MeshFormat header)")
    try:
        import gmsh
    except ImportError:
        raise Failure(f"{key}: reading '{path}' needs the gmsh Python module (Debian "
                      "python3-gmsh; ./fsi deps installs it)")
    argv = ["gmsh"]
    for name, value in parameters:
        argv += ["-setnumber", name, f"{value:.17g}"]
    gmsh.initialize(argv, readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 1)
        try:
            gmsh.open(path)
            if ext == ".geo":
                gmsh.option.setNumber("Mesh.MeshSizeFactor", size_factor)
                gmsh.model.mesh.generate(2)
            for _ in range(refine):
                gmsh.model.mesh.refine()
        except Exception as e:
            raise Failure(f"{key}: Gmsh could not read '{path}': {e}")
        tags, coord, _ = gmsh.model.mesh.getNodes(-1, -1, False, False)
        tris = []
        for dim, tag in gmsh.model.getEntities(2):
            types, _, enodes = gmsh.model.mesh.getElements(2, tag)
            for ty, nodes in zip(types, enodes):
                if ty != 2:
                    raise Failure(f"{key}: mesh '{path}' has surface elements of Gmsh type {ty}; "
                                  "only 3-node triangles are supported")
                tris.append(np.asarray(nodes, dtype=np.int64).reshape(-1, 3))
    finally:
        gmsh.finalize()
    if not tris:
        raise Failure(f"{key}: mesh '{path}' holds no triangles (is it a 2D Gmsh mesh?)")
    tris = np.concatenate(tris)
    # The nodes that triangles use, numbered in the order of Gmsh's node list (as solid/ does).
    tags = np.asarray(tags, dtype=np.int64)
    index = {int(t): k for k, t in enumerate(tags)}
    used = np.zeros(len(tags), dtype=bool)
    rows = np.array([index[int(n)] for n in tris.ravel()], dtype=np.int64)
    used[rows] = True
    new = -np.ones(len(tags), dtype=np.int64)
    new[used] = np.arange(used.sum())
    x = np.asarray(coord, dtype=float).reshape(-1, 3)[used, :2].ravel()
    return x, new[rows].reshape(-1, 3).astype(np.int32)


def rectangle(t):
    """solid/'s built-in structured rectangle (solid/mesh.cpp rectangle_mesh)."""
    x0, y0 = t.vec2("origin", [0.0, 0.0])
    lx, ly = t.vec2("size")
    if not (lx > 0 and ly > 0):
        t.fail("size", f"must be positive, got [{lx}, {ly}]")
    cells = t.get("cells", None, list)
    if (len(cells) != 2 or any(isinstance(c, bool) or not isinstance(c, (int, float)) for c in cells)
            or any(c < 1 or c != math.floor(c) for c in cells)):
        t.fail("cells", "must be two integers >= 1, [nx, ny]")
    nx, ny = int(cells[0]), int(cells[1])
    d = t.get("diagonals", "criss-cross", str)
    if d not in ("criss-cross", "right", "left", "union-jack"):
        t.fail("diagonals", f'must be one of "criss-cross", "right", "left", "union-jack", got "{d}"')
    t.get("region", "body", str)
    t.finish()
    x = []
    for j in range(ny + 1):
        for i in range(nx + 1):
            x += [x0 + lx if i == nx else x0 + lx * i / nx, y0 + ly if j == ny else y0 + ly * j / ny]
    tri = []

    def node(i, j):
        return j * (nx + 1) + i
    for j in range(ny):
        for i in range(nx):
            a, b, c, e = node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)
            if d == "union-jack":
                centre = len(x) // 2
                x += [x0 + lx * (i + 0.5) / nx, y0 + ly * (j + 0.5) / ny]
                tri += [[a, b, centre], [b, c, centre], [c, e, centre], [e, a, centre]]
            elif d == "right" or (d == "criss-cross" and (i + j) % 2 == 0):
                tri += [[a, b, c], [a, c, e]]
            else:
                tri += [[a, b, e], [b, c, e]]
    return np.array(x, dtype=float), np.array(tri, dtype=np.int32)


def read_mesh(b, scene_dir):
    """(x_ref, triangles, source) of the body table b: `mesh = "file.geo"` or [rectangle]."""
    has_file, has_rect = b.has("mesh"), b.has("rectangle")
    if has_file == has_rect:
        raise Failure(f"{b.path}: give the mesh either as mesh = \"file.geo\" (or .msh) or as a "
                      f"[rectangle] table (in {b.file})")
    if has_file:
        name = b.get("mesh", None, str)
        path = name if os.path.isabs(name) else os.path.join(scene_dir, name)
        size_factor = b.get("mesh_size_factor", 1.0, float)
        if not size_factor > 0:
            b.fail("mesh_size_factor", f"must be > 0, got {size_factor}")
        refine = b.get("mesh_refine", 0, int)
        if not 0 <= refine <= MAX_REFINE:
            b.fail("mesh_refine", f"must be in [0, {MAX_REFINE}], got {refine}")
        params = parse_parameters(b, "mesh_parameters") if b.has("mesh_parameters") else []
        x, tri = read_gmsh(path, params, size_factor, refine, b.key("mesh"))
        source = path
    else:
        x, tri = rectangle(b.sub("rectangle"))
        source = "rectangle"
    return x, orient(x, tri, source), source


def orient(x, tri, source):
    """Counter-clockwise triangles: a mesh wound clockwise throughout is turned; a degenerate or
    a mixed one is an error (solid/ refuses them too)."""
    p = x.reshape(-1, 2)
    a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    scale = np.max(np.abs(p - p.mean(axis=0))) ** 2
    bad = np.flatnonzero(np.abs(area2) <= 1e-14 * scale)
    if bad.size:
        raise Failure(f"mesh {source}: element {bad[0]} is degenerate (zero area)")
    if np.all(area2 < 0):
        tri = tri[:, [0, 2, 1]]
    elif np.any(area2 < 0):
        raise Failure(f"mesh {source}: element {np.flatnonzero(area2 < 0)[0]} is inverted: its "
                      "orientation is opposite to the others'")
    return np.ascontiguousarray(tri, dtype=np.int32)


def surface_edges(tri):
    """Edges of exactly one triangle, in the triangle's (counter-clockwise) order."""
    count = {}
    for t in tri:
        for k in range(3):
            a, b = int(t[k]), int(t[(k + 1) % 3])
            key = (min(a, b), max(a, b))
            count[key] = count.get(key, 0) + 1
    return np.array([[int(t[k]), int(t[(k + 1) % 3])] for t in tri for k in range(3)
                     if count[(min(t[k], t[(k + 1) % 3]), max(t[k], t[(k + 1) % 3]))] == 1],
                    dtype=np.int32)

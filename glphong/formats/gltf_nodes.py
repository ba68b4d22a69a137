"""The node hierarchy of a glTF 2.0 document: each node's local matrix, the paths a scene reaches it by, and the
check that the hierarchy can be drawn.

The specification asks for a forest (each node one parent at most, listed once).  Files from some exporters (game
kits, instanced props) share a subtree between two parents, list a node twice in one ``children``, or list a child as
a scene root too; three.js, Blender and trimesh draw such a node once per path, and so does glphong (`node_worlds`),
with one warning naming the node and its parents (`check_hierarchy`).  Only a cycle (a node its own ancestor) is an
error.  Shared subtrees multiply: 30 levels of two parents make 2^30 paths, so the number of paths (node instances)
a scene reaches is counted before any is walked and bounded by ``Limits.nodes``, like the nodes themselves: a shared
hierarchy cannot draw more than a flat file of the same limit.
"""
import warnings

import numpy as np

from glphong.core.filesafety import LIMITS, SceneFileError

__all__ = ["local_matrix", "scene_roots", "node_worlds", "check_hierarchy"]


def local_matrix(node):
    """The (4, 4) float64 local matrix of a validated glTF node: its ``matrix`` (column-major in the file), else
    ``T R S`` of its ``translation``, ``rotation`` (a unit quaternion x, y, z, w) and ``scale``."""
    if "matrix" in node:
        return np.asarray(node["matrix"], dtype=np.float64).reshape(4, 4).T  # column-major in glTF
    t = np.asarray(node.get("translation", (0.0, 0.0, 0.0)), dtype=np.float64)
    x, y, z, w = node.get("rotation", (0.0, 0.0, 0.0, 1.0))
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r * np.asarray(node.get("scale", (1.0, 1.0, 1.0)), dtype=np.float64)
    m[:3, 3] = t
    return m


def scene_roots(document, scene=None):
    """``(roots, where)``: the node indices scene ``scene`` (default: the document's ``scene``, else 0) lists and its
    JSON path; without a ``scenes`` array, every node that is no node's child, in file order (where ``'nodes'``)."""
    scenes = document.get("scenes")
    if scenes:
        chosen = document.get("scene", 0) if scene is None else scene
        return list(scenes[chosen].get("nodes", [])), f"scenes[{chosen}].nodes"
    nodes = document.get("nodes", [])
    children = {c for node in nodes for c in node.get("children", [])}
    return [k for k in range(len(nodes)) if k not in children], "nodes"


def node_worlds(document, limits=None):
    """The world matrices of every node the default scene reaches: {node index: [(4, 4) float64 world, ...]}, one
    matrix per path from a root, in depth-first order (a node shared by two parents has two).

    The walk is iterative (a legal chain thousands of nodes deep loads).  A document `check_hierarchy` passed has no
    cycle and at most ``Limits.nodes`` paths; the walk stops at that many all the same, so it can never loop.
    """
    limit = (limits or LIMITS).nodes
    nodes = document.get("nodes", [])
    roots, where = scene_roots(document)
    out, walked = {}, 0
    stack = [(root, np.eye(4)) for root in reversed(roots)]
    while stack:
        index, parent = stack.pop()
        walked += 1
        if walked > limit:  # unreachable for a validated document
            raise SceneFileError("(glTF document)", f"more than {limit} node instances", where)
        world = parent @ local_matrix(nodes[index])
        out.setdefault(index, []).append(world)
        stack.extend((child, world) for child in reversed(nodes[index].get("children", [])))
    return out


def _cycle(c, nodes):
    """Fail with the JSON path of a child link that closes a cycle (iterative depth-first search, colours: 1 on the
    current path, 2 done)."""
    state = {}
    for start in range(len(nodes)):
        if state.get(start):
            continue
        state[start] = 1
        path, work = [start], [(start, enumerate(nodes[start].get("children", [])))]
        while work:
            node, children = work[-1]
            for j, child in children:
                if state.get(child) == 1:
                    loop = " -> ".join(map(str, path[path.index(child):] + [child]))
                    c.fail(f"nodes[{node}].children[{j}]", f"node {child} is its own ancestor (the cycle {loop}): "
                           "a node may be shared by several parents, never reached from itself")
                if not state.get(child):
                    state[child] = 1
                    path.append(child)
                    work.append((child, enumerate(nodes[child].get("children", []))))
                    break
            else:
                state[node] = 2
                path.pop()
                work.pop()


def _topological(nodes):
    """Node indices, every parent before its children (the document is acyclic)."""
    order, done = [], set()
    for start in range(len(nodes)):
        if start in done:
            continue
        done.add(start)
        work = [(start, iter(nodes[start].get("children", [])))]
        while work:
            node, children = work[-1]
            for child in children:
                if child not in done:
                    done.add(child)
                    work.append((child, iter(nodes[child].get("children", []))))
                    break
            else:
                order.append(node)
                work.pop()
    return order[::-1]


def check_hierarchy(c):
    """The node hierarchy of a document whose indices are checked (``c``: `glphong.formats.gltf_validate`'s checker):
    a cycle fails with the child link that closes it; the paths (node instances) of the scene drawn (`scene_roots`)
    are counted, parents first, and more than ``Limits.nodes`` fails; a node reached by several links is named in one
    warning per file."""
    nodes = c.document.get("nodes", [])
    _cycle(c, nodes)
    limit = c.limits.nodes
    roots, where = scene_roots(c.document)
    paths, links = [0] * len(nodes), {}  # links: node -> the parents that list it (-1: the scene)
    for root in roots:
        paths[root] += 1
        links.setdefault(root, []).append(-1)
    for node in _topological(nodes):  # parents first: a node's count is final before its children read it
        if paths[node]:
            for child in nodes[node].get("children", []):
                paths[child] = min(paths[child] + paths[node], limit + 1)  # bounded: no huge integers
                links.setdefault(child, []).append(node)
    if sum(paths) > limit:
        c.fail(where.rpartition(".nodes")[0] or where, f"its nodes are reached by more than {limit} paths (node "
               "instances: shared subtrees multiply them; glphong.filesafety.Limits.nodes)")
    shared = sorted((node, reach) for node, reach in links.items() if len(reach) > 1)  # nodes are unique keys
    if shared:
        node, reach = shared[0]
        reach = [where if parent < 0 else f"nodes[{parent}]" for parent in sorted(reach)]
        name = nodes[node].get("name")
        named = f"nodes[{node}]" + (f" ({name!r:.40})" if isinstance(name, str) else "")
        more = f"; {len(shared) - 1} other node(s) too" if len(shared) > 1 else ""
        warnings.warn(f"{c.path}: {named} is listed by {len(reach)} parents or scene lists ({', '.join(reach[:6])}"
                      f"{', ...' if len(reach) > 6 else ''}){more}: the glTF specification asks for a tree; glphong "
                      f"draws it once per path ({paths[node]} instances here), as three.js and Blender do",
                      stacklevel=5)

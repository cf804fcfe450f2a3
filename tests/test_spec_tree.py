"""Spec elements' hand-written methods (issue 13, mjcffi/spec/elements.py): the
kinematic tree (first_*/next_*, child lists, find_all, parent, frames, children,
subtree), to_frame, attach_body/attach_frame, make_flex, the built-in meshes,
sensor sizes, tendon paths and the common element properties, against the
official bindings."""

import gc
import glob
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import mjcffi
from mjcffi import MjSpec, mjtObj
from mjcffi._support import elements as _elements

gymnasium = pytest.importorskip("gymnasium")
ASSET_DIR = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets")
ASSETS = sorted(glob.glob(os.path.join(ASSET_DIR, "*.xml")))
HUMANOID = os.path.join(ASSET_DIR, "humanoid.xml")

KINDS = ("body", "frame", "geom", "site", "joint", "light", "camera")
PLURALS = {"body": "bodies", "frame": "frames", "geom": "geoms", "site": "sites",
           "joint": "joints", "light": "lights", "camera": "cameras"}

TREE = """
<mujoco>
  <worldbody>
    <body name="a">
      <geom name="g1" size="1"/>
      <frame name="f">
        <site name="s1"/>
      </frame>
      <body name="a1">
        <joint name="j1"/>
        <geom name="g3" size="1"/>
      </body>
      <geom name="g2" size="1"/>
      <camera name="c1"/>
    </body>
    <body name="b">
      <geom name="g4" size="1"/>
      <light name="l1"/>
    </body>
  </worldbody>
</mujoco>
"""


def assert_ended(wrapper):
    """`wrapper` is that of a freed element: whatever it still reads, it writes
    nothing, and it reaches MuJoCo no more (its tree methods raise)."""
    assert isinstance(wrapper, _elements.DeletedElement)
    with pytest.raises((ValueError, RuntimeError), match="deleted"):
        wrapper.name = "again"
    if isinstance(wrapper, mjcffi.MjsBody):
        with pytest.raises((ValueError, RuntimeError), match="deleted"):
            wrapper.first_geom()


def names(elements):
    return [e.name for e in elements]


def chain(body, kind):
    """The names of `body`'s children of `kind` through first_*/next_*."""
    found, element = [], getattr(body, f"first_{kind}")()
    while element is not None:
        found.append(element.name)
        element = getattr(body, f"next_{kind}")(element)
    return found


# ------------------------------------------------------------------ traversal

@pytest.mark.parametrize("path", ASSETS, ids=os.path.basename)
def test_child_lists_and_find_all_match_official(path, mujoco):
    ours, theirs = MjSpec.from_file(path), mujoco.MjSpec.from_file(path)
    assert len(ours.bodies) == len(theirs.bodies) > 1
    for mine, official in zip(ours.bodies, theirs.bodies):
        assert mine.name == official.name
        for kind in KINDS:
            plural = PLURALS[kind]
            assert names(getattr(mine, plural)) == names(getattr(official, plural)), plural
            assert chain(mine, kind) == names(getattr(official, plural)), kind
            assert names(mine.find_all(kind)) == names(official.find_all(kind)), kind
        parent = official.parent
        assert (mine.parent.name if mine.parent else None) == \
            (parent.name if parent else None)


def test_humanoid_subtree_is_the_compiled_body_order(mujoco):
    spec = MjSpec.from_file(HUMANOID)
    model = spec.compile()
    order = names(spec.worldbody.subtree())
    assert order == [model.body(i).name for i in range(model.nbody)]
    assert order == names(spec.bodies)
    torso = spec.body("torso")
    assert torso.subtree()[0] is torso
    assert names(torso.subtree()[1:]) == names(torso.find_all("body"))
    official = mujoco.MjSpec.from_file(HUMANOID).body("torso")
    assert names(torso.subtree()[1:]) == names(official.find_all("body"))


def test_children_are_the_direct_child_bodies():
    spec = MjSpec.from_file(HUMANOID)
    torso = spec.body("torso")
    assert torso.children() == torso.bodies
    assert names(torso.children()) == ["lwaist", "right_upper_arm", "left_upper_arm"]
    assert names(spec.worldbody.children()) == ["torso"]
    for body in spec.bodies:
        for child in body.children():
            assert child.parent is body
    leaves = [b for b in spec.bodies if not b.children()]
    assert leaves and all(b.first_body() is None for b in leaves)


def test_parent_of_world_is_none_and_of_every_element_its_body():
    spec = MjSpec.from_string(TREE)
    assert spec.worldbody.parent is None
    assert spec.body("a").parent is spec.worldbody
    assert spec.body("a1").parent is spec.body("a")
    assert spec.site("s1").parent is spec.body("a")
    assert spec.frame("f").parent is spec.body("a")
    assert spec.joint("j1").parent is spec.body("a1")
    assert spec.camera("c1").parent is spec.body("a")
    assert spec.light("l1").parent is spec.body("b")


def test_traversal_returns_the_one_wrapper_of_each_element():
    spec = MjSpec.from_string(TREE)
    a = spec.body("a")
    assert a.first_geom() is spec.geom("g1")
    assert a.next_geom(a.first_geom()) is spec.geom("g2")
    assert a.next_geom(spec.geom("g2")) is None
    assert a.first_body() is spec.body("a1")
    assert a.first_light() is None
    assert spec.worldbody.find_all("site")[0] is spec.site("s1")


def test_next_of_an_element_elsewhere_is_none():
    spec = MjSpec.from_string(TREE)
    assert spec.body("a").next_geom(spec.geom("g4")) is None
    assert spec.body("a").next_body(spec.worldbody) is None


def test_find_all_order_and_types(mujoco):
    spec, official = MjSpec.from_string(TREE), mujoco.MjSpec.from_string(TREE)
    for kind in KINDS:
        assert names(spec.worldbody.find_all(kind)) == \
            names(official.worldbody.find_all(kind))
    assert names(spec.worldbody.find_all(mjtObj.mjOBJ_GEOM)) == ["g1", "g2", "g3", "g4"]
    assert names(spec.body("a").find_all(mjtObj.mjOBJ_BODY)) == ["a1"]
    assert spec.body("b").find_all("body") == []


def test_find_all_refuses_other_types(mujoco):
    spec = MjSpec.from_string(TREE)
    message = ("body.find_all supports the types: body, frame, geom, site, joint, light, "
               "camera.")
    for bad in ("actuator", "bogus", mjtObj.mjOBJ_MESH):
        with pytest.raises(ValueError) as caught:
            spec.worldbody.find_all(bad)
        assert str(caught.value) == message
    with pytest.raises(ValueError, match="find_all supports"):
        mujoco.MjSpec.from_string(TREE).worldbody.find_all("actuator")
    with pytest.raises(TypeError, match="mjtObj or str"):
        spec.worldbody.find_all(5.5)


def test_find_child_searches_the_subtree(mujoco):
    spec = MjSpec.from_string(TREE)
    assert spec.worldbody.find_child("a1") is spec.body("a1")
    assert spec.body("b").find_child("a1") is None
    assert mujoco.MjSpec.from_string(TREE).worldbody.find_child("a1").name == "a1"
    with pytest.raises(TypeError):
        spec.worldbody.find_child(3)


def test_bad_arguments_to_next_raise():
    spec, other = MjSpec.from_string(TREE), MjSpec.from_string(TREE)
    a = spec.body("a")
    with pytest.raises(TypeError, match="must be an MjsGeom, not MjsBody"):
        a.next_geom(spec.body("a1"))
    with pytest.raises(TypeError, match="not NoneType"):
        a.next_body(None)
    with pytest.raises(ValueError, match="another spec"):
        a.next_geom(other.geom("g1"))
    geom = spec.geom("g1")
    spec.delete(geom)
    with pytest.raises(ValueError, match="deleted"):
        a.next_geom(geom)


def test_iterating_while_deleting_never_reads_freed_memory():
    spec = MjSpec.from_string(TREE)
    bodies = spec.worldbody.subtree()
    spec.delete(spec.body("a"))
    assert names(spec.worldbody.subtree()) == ["world", "b"]
    assert_ended(bodies[1])          # "a", freed
    assert bodies[-1].name == "b"


# --------------------------------------------------------------------- frames

def test_set_frame_and_frame():
    spec = MjSpec()
    body = spec.worldbody.add_body()
    frame = body.add_frame()
    geom = body.add_geom()
    assert geom.frame is None
    geom.set_frame(frame)
    assert geom.frame is frame
    assert frame.frame is None
    inner = body.add_frame()
    inner.set_frame(frame)
    assert inner.frame is frame


def test_set_frame_refusals(mujoco):
    spec = MjSpec.from_string(TREE)
    other = MjSpec()
    with pytest.raises(ValueError, match="another spec"):
        spec.geom("g1").set_frame(other.worldbody.add_frame())
    with pytest.raises(TypeError, match="MjsFrame"):
        spec.geom("g1").set_frame(None)
    with pytest.raises(TypeError, match="MjsFrame"):
        spec.geom("g1").set_frame(spec.body("a"))
    # a frame of another body: MuJoCo's own refusal, worded as the official's
    with pytest.raises(ValueError) as ours:
        spec.body("b").set_frame(spec.frame("f"))
    official = mujoco.MjSpec.from_string(TREE)
    with pytest.raises(ValueError) as theirs:
        official.body("b").set_frame(official.frame("f"))
    assert str(ours.value) == str(theirs.value)


def test_to_frame(mujoco):
    def build(module):
        spec = module.MjSpec()
        body = spec.worldbody.add_body(name="b", pos=[1, 2, 3])
        body.add_geom(name="g", size=[0.1, 0, 0])
        body.add_body(name="c").add_geom(size=[0.1, 0, 0])
        return spec, body

    spec, body = build(mjcffi)
    geom, child = spec.geom("g"), spec.body("c")
    frame = body.to_frame()
    np.testing.assert_array_equal(frame.pos, [1, 2, 3])
    assert frame.parent is spec.worldbody
    assert geom.parent is spec.worldbody and geom.frame is frame
    assert child.parent is spec.worldbody and child.frame is frame
    assert_ended(body)
    official, official_body = build(mujoco)
    official_body.to_frame()
    ours, theirs = spec.compile(), official.compile()
    assert ours.nbody == theirs.nbody == 2
    np.testing.assert_array_equal(ours.body_pos, theirs.body_pos)
    np.testing.assert_array_equal(ours.geom_pos, theirs.geom_pos)


def test_to_frame_is_refused_while_views_of_the_body_are_held():
    spec = MjSpec()
    body = spec.worldbody.add_body(name="b", pos=[1, 2, 3])
    pos = body.pos
    with pytest.raises(ValueError, match="NumPy arrays still view"):
        body.to_frame()
    assert body.name == "b" and pos.tolist() == [1, 2, 3]
    del pos
    assert body.to_frame().pos.tolist() == [1, 2, 3]


def test_world_body_to_frame_is_refused():
    spec = MjSpec()
    with pytest.raises(ValueError, match="world body"):
        spec.worldbody.to_frame()
    assert spec.worldbody.name == "world"
    assert spec.compile().nbody == 1


# --------------------------------------------------------------------- attach

def child_spec(name="b"):
    child = MjSpec()
    body = child.worldbody.add_body(name=name)
    body.add_geom(name="g", size=[0.1, 0, 0])
    return child, body


def test_attach_body_to_frame_moves_the_element():
    parent = MjSpec()
    frame = parent.worldbody.add_frame(pos=[1, 2, 3], quat=[0, 0, 0, 1])
    child, body = child_spec()
    geom = child.geom("g")
    assert frame.attach_body(body, prefix="c-") is body
    assert body.name == "c-b"
    assert parent.body("c-b") is body
    assert parent.geom("c-g") is geom
    assert body.parent is parent.worldbody and body.frame is frame
    body.pos = [1, 1, 1]
    model = parent.compile()
    assert model.nbody == 2
    np.testing.assert_array_equal(model.body_pos[1], [0, 1, 4])


def test_attach_body_to_site(mujoco):
    def build(module):
        parent = module.MjSpec()
        site = parent.worldbody.add_site(name="s", pos=[1, 2, 3], quat=[0, 0, 0, 1])
        child = module.MjSpec()
        body = child.worldbody.add_body(name="b", pos=[1, 1, 1])
        body.add_geom(size=[0.1, 0, 0])
        assert site.attach_body(body, "p-", "-s") is body
        return parent
    ours, theirs = build(mjcffi).compile(), build(mujoco).compile()
    assert ours.nbody == theirs.nbody == 2
    assert ours.body(1).name == theirs.body(1).name == "p-b-s"
    np.testing.assert_array_equal(ours.body_pos, theirs.body_pos)
    np.testing.assert_array_equal(ours.body_quat, theirs.body_quat)


def test_attach_frame_to_body():
    parent = MjSpec()
    body = parent.worldbody.add_body(name="holder", pos=[0, 0, 1])
    child = MjSpec()
    frame = child.worldbody.add_frame(name="f", pos=[1, 0, 0])
    frame.add_body(name="inner").add_geom(size=[0.1, 0, 0])
    assert body.attach_frame(frame, "x-") is frame
    assert frame.parent is body
    assert parent.body("x-inner").parent is body
    model = parent.compile()
    assert model.nbody == 3
    np.testing.assert_allclose(model.body("x-inner").pos, [1, 0, 0])


def test_deleting_an_attached_body_from_the_parent_ends_its_wrappers():
    parent = MjSpec()
    frame = parent.worldbody.add_frame()
    child, body = child_spec()
    geom = child.geom("g")
    frame.attach_body(body, "c-")
    late = body.add_geom(name="late", size=[0.1, 0, 0])    # made after the attach
    assert parent.geom("late") is late
    parent.delete(body)
    for wrapper in (body, geom, late):
        assert_ended(wrapper)
    assert parent.compile().nbody == 1


def test_attach_refusals(mujoco):
    parent = MjSpec()
    frame = parent.worldbody.add_frame()
    own = parent.worldbody.add_body(name="own")
    with pytest.raises(ValueError, match="Child element is in the parent spec"):
        frame.attach_body(own, "x-")
    with pytest.raises(TypeError, match="must be an MjsBody"):
        frame.attach_body(frame, "x-")
    with pytest.raises(TypeError, match="not NoneType"):
        frame.attach_body(None)
    with pytest.raises(TypeError, match="prefix"):
        frame.attach_body(child_spec()[1], prefix=3)
    child, body = child_spec()
    child.delete(body)
    with pytest.raises(ValueError, match="deleted"):
        frame.attach_body(body, "x-")
    assert parent.compile().nbody == 2


def test_attach_conflict_leaves_the_parent_as_it_was():
    parent = MjSpec()
    parent.compiler.conflict = mjcffi.mjtConflict.mjCONFLICT_MERGE
    parent.option.integrator = mjcffi.mjtIntegrator.mjINT_RK4
    child, body = child_spec()
    child.option.integrator = mjcffi.mjtIntegrator.mjINT_IMPLICIT
    frame = parent.worldbody.add_frame()
    with pytest.raises(ValueError, match="integrator"):
        frame.attach_body(body, prefix="c-")
    assert parent.option.integrator == mjcffi.mjtIntegrator.mjINT_RK4
    assert parent.compile().nbody == 1


def test_attached_body_outlives_its_spec_object():
    script = textwrap.dedent("""
        import gc
        import mjcffi

        def attached(frame):
            child = mjcffi.MjSpec()
            body = child.worldbody.add_body(name="b")
            body.add_geom(size=[0.1, 0, 0])
            frame.attach_body(body, "c-")

        parent = mjcffi.MjSpec()
        frame = parent.worldbody.add_frame()
        attached(frame)
        gc.collect()
        body = parent.body("c-b")
        body.pos = [0, 0, 2]
        print(parent.compile().nbody, body.first_geom().size[0], body.parent.name)
        parent.delete(body)
        print(parent.compile().nbody)
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["2", "0.1", "world", "1"]


# ---------------------------------------------------------------- make_flex

def test_make_flex_grid_matches_official(mujoco):
    def build(module):
        spec = module.MjSpec()
        body = spec.worldbody.add_body(name="holder")
        flex = body.make_flex(name="cloth", type="grid", dim=2, count=[4, 3, 1],
                              spacing=[0.1, 0.1, 0.1], mass=0.5, equality=1,
                              pos=[0, 0, 1], quat=[1, 0, 0, 0])
        assert flex.name == "cloth"
        return spec.compile()
    ours, theirs = build(mjcffi), build(mujoco)
    for size in ("nflex", "nflexvert", "nbody", "njnt", "neq"):
        assert getattr(ours, size) == getattr(theirs, size), size
    assert ours.nflexvert == 12
    np.testing.assert_array_equal(ours.body_pos, theirs.body_pos)


def test_make_flex_from_a_mesh_asset(mujoco):
    def build(module):
        spec = module.MjSpec()
        spec.add_mesh(name="tet").make_grid(count=[3, 3, 3], spacing=[0.1, 0.1, 0.1])
        spec.worldbody.add_body(name="holder").make_flex(name="solid", mesh="tet",
                                                         equality=1)
        return spec.compile()
    ours, theirs = build(mjcffi), build(mujoco)
    assert ours.nflex == theirs.nflex == 1
    assert ours.flex_dim[0] == theirs.flex_dim[0] == 3
    assert ours.nflexvert == theirs.nflexvert == 27


def test_make_flex_from_a_file_in_a_vfs(mujoco):
    tetrahedron = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"
    models = []
    for module in (mjcffi, mujoco):
        with module.MjVfs() as vfs:
            vfs["tet.obj"] = tetrahedron
            spec = module.MjSpec()
            spec.worldbody.add_body(name="h").make_flex(
                name="skin", type="mesh", dim=2, file="tet.obj", vfs=vfs, equality=1)
            models.append(spec.compile())
    assert models[0].nflexvert == models[1].nflexvert == 4
    assert models[0].flex_dim[0] == models[1].flex_dim[0] == 2
    body = MjSpec().worldbody.add_body(name="h")
    with pytest.raises(ValueError, match="neither a mesh asset nor a file"):
        body.make_flex(name="a", type="mesh", dim=2, file="missing.obj")
    with pytest.raises(TypeError, match="vfs"):
        body.make_flex(name="a", type="mesh", file="tet.obj", vfs="tet.obj")


def test_make_flex_refusals():
    spec = MjSpec()
    spec.add_mesh(name="m").make_grid(count=[3, 3, 1], spacing=[0.1, 0.1, 0], dim=2)
    body = spec.worldbody.add_body(name="holder")
    with pytest.raises(ValueError, match="mesh 'nope' not found"):
        body.make_flex(name="a", mesh="nope")
    with pytest.raises(ValueError, match="both 'file' and 'mesh'"):
        body.make_flex(name="a", mesh="m", file="m.obj")
    with pytest.raises(ValueError, match="count must have 3 elements"):
        body.make_flex(name="a", count=[3, 3])
    with pytest.raises(TypeError, match="dim must be an int"):
        body.make_flex(name="a", dim=2.5)
    with pytest.raises(ValueError, match="is out of range for a C int"):
        body.make_flex(name="a", count=[2 ** 40, 2, 2])
    with pytest.raises(ValueError, match="Invalid dim"):
        body.make_flex(name="a", dim=4)
    with pytest.raises(TypeError, match="name"):
        body.make_flex(name=None)
    with pytest.raises(ValueError, match="Parent body must have name"):
        spec.worldbody.add_body().make_flex(name="a")
    assert spec.flexes == []


# ---------------------------------------------------------- built-in meshes

MESHES = [
    ("make_sphere", {"subdivision": 2}),
    ("make_hemisphere", {"resolution": 4}),
    ("make_cone", {"nedge": 5, "radius": 0.5}),
    ("make_supersphere", {"resolution": 12, "e": 2, "n": 1}),
    ("make_supertorus", {"resolution": 10, "radius": 0.5, "s": 1, "t": 1}),
    ("make_wedge", {"resolution": [5, 6], "fov": [90, 45], "gamma": 0.2}),
    ("make_plate", {"resolution": [3, 4]}),
    ("make_grid", {"count": [4, 4, 4], "spacing": [0.05, 0.05, 0.05]}),
    ("make_grid", {"count": [4, 3, 1], "spacing": [0.05, 0.05, 0], "dim": 2}),
    ("make_box", {"count": [3, 3, 3], "spacing": [0.05, 0.05, 0.05], "dim": 2}),
    ("make_cylinder", {"count": [3, 3, 3], "spacing": [0.05, 0.05, 0.05]}),
    ("make_ellipsoid", {"count": [3, 3, 3], "spacing": [0.05, 0.05, 0.05]}),
    ("make_square", {"count": [4, 4, 1], "spacing": [0.05, 0.05, 0]}),
    ("make_disc", {"count": [5, 5, 1], "spacing": [0.05, 0.05, 0]}),
]


@pytest.mark.parametrize("method, kwargs", MESHES, ids=[m for m, _ in MESHES])
def test_builtin_meshes_match_official(method, kwargs, mujoco):
    meshes = []
    for module in (mjcffi, mujoco):
        mesh = module.MjSpec().add_mesh(name="m")
        assert getattr(mesh, method)(**kwargs) is None
        meshes.append(mesh)
    ours, theirs = meshes
    for field in ("uservert", "userface", "usernormal", "usernode", "usertet"):
        np.testing.assert_array_equal(getattr(ours, field), getattr(theirs, field), field)
    assert ours.uservert.size > 0 or ours.usernode.size > 0


def test_builtin_mesh_vertex_counts():
    spec = MjSpec()
    spec.add_mesh(name="sphere").make_sphere(subdivision=2)
    spec.add_mesh(name="cone").make_cone(nedge=6, radius=0)
    spec.add_mesh(name="supersphere").make_supersphere(resolution=20, e=2, n=1)
    model = spec.compile()
    assert list(model.mesh_vertnum) == [2 + 10 * 4 ** 2, 7, 20 * 19 + 2]


def test_builtin_mesh_refusals():
    mesh = MjSpec().add_mesh(name="m")
    with pytest.raises(ValueError, match="Sphere subdivision cannot be greater than 4"):
        mesh.make_sphere(subdivision=10)
    with pytest.raises(ValueError, match="Cone nvert must be at least 3"):
        mesh.make_cone(nedge=2, radius=1)
    with pytest.raises(ValueError, match="count and spacing must have 3 elements"):
        mesh.make_grid(count=[4, 4], spacing=[0.1, 0.1, 0.1])
    with pytest.raises(ValueError, match="resolution must have 2 elements"):
        mesh.make_wedge(resolution=[1, 2, 3])
    with pytest.raises(TypeError, match="subdivision must be an int"):
        mesh.make_sphere(subdivision=1.5)
    with pytest.raises(TypeError, match="subdivision must be an int"):
        mesh.make_sphere(subdivision="2")
    with pytest.raises(TypeError, match="count must hold ints"):
        mesh.make_grid(count=[4, 4, 4.5], spacing=[0.1, 0.1, 0.1])
    assert mesh.uservert.size == 0


def test_mesh_material_follows_the_mesh():
    spec = MjSpec()
    spec.add_material(name="red", rgba=[1, 0, 0, 1])
    spec.add_material(name="green", rgba=[0, 1, 0, 1])
    mesh = spec.add_mesh(name="sphere")
    mesh.make_sphere(subdivision=1)
    mesh.material = "red"
    spec.worldbody.add_geom(type=mjcffi.mjtGeom.mjGEOM_MESH, meshname="sphere")
    assert spec.compile().geom_matid[0] == 0
    mesh.material = "green"
    assert spec.compile().geom_matid[0] == 1


# ------------------------------------------------------------------ sensors

SENSORS = [
    (mjcffi.mjtSensor.mjSENS_FRAMEQUAT, mjtObj.mjOBJ_BODY, "world"),
    (mjcffi.mjtSensor.mjSENS_FRAMEPOS, mjtObj.mjOBJ_BODY, "world"),
    (mjcffi.mjtSensor.mjSENS_CLOCK, mjtObj.mjOBJ_UNKNOWN, ""),
    (mjcffi.mjtSensor.mjSENS_SUBTREECOM, mjtObj.mjOBJ_BODY, "world"),
    (mjcffi.mjtSensor.mjSENS_ACCELEROMETER, mjtObj.mjOBJ_SITE, "s"),
    (mjcffi.mjtSensor.mjSENS_TOUCH, mjtObj.mjOBJ_SITE, "s"),
]


def test_sensor_data_size_matches_official_and_the_model(mujoco):
    sizes = []
    for module in (mjcffi, mujoco):
        spec = module.MjSpec()
        spec.worldbody.add_site(name="s")
        sensors = [spec.add_sensor(type=int(t), objtype=int(o), objname=n)
                   for t, o, n in SENSORS]
        sizes.append([s.get_data_size() for s in sensors])
        if module is mjcffi:
            assert list(spec.compile().sensor_dim) == sizes[0]
    assert sizes[0] == sizes[1]
    assert sizes[0][:3] == [4, 3, 1]


# ------------------------------------------------------------------ tendons

def test_humanoid_tendon_paths_match_official(mujoco):
    ours, theirs = MjSpec.from_file(HUMANOID), mujoco.MjSpec.from_file(HUMANOID)
    assert len(ours.tendons) == len(theirs.tendons) > 0
    for mine, official in zip(ours.tendons, theirs.tendons):
        assert len(mine.path) == len(official.path) > 0
        for a, b in zip(mine.path, official.path):
            assert a.type == b.type
            assert a.target.name == b.target.name
            assert a.coef == b.coef and a.divisor == b.divisor
            assert a.sidesite is None and b.sidesite is None


def test_tendon_path_of_every_wrap_kind():
    spec = MjSpec()
    body = spec.worldbody.add_body(name="b")
    body.add_geom(name="bg", size=[0.1, 0, 0])
    s1 = body.add_site(name="s1")
    s2 = body.add_site(name="s2", pos=[0, 0, -2])
    side = body.add_site(name="side", pos=[1, 0, -1])
    ball = spec.worldbody.add_geom(name="ball", size=[0.2, 0, 0], pos=[0, 0, -1])
    joint = body.add_joint(name="j", type=mjcffi.mjtJoint.mjJNT_HINGE)
    spatial, fixed = spec.add_tendon(), spec.add_tendon()
    wraps = [spatial.wrap_site("s1"), spatial.wrap_geom("ball", "side"),
             spatial.wrap_site("s2"), spatial.wrap_pulley(2.0), spatial.wrap_site("s1")]
    joint_wrap = fixed.wrap_joint("j", 3.0)
    path = spatial.path
    assert len(path) == 5
    assert list(path) == wraps and path[-1] is wraps[-1]
    assert path[1:3] == wraps[1:3]
    assert [w.target for w in path] == [s1, ball, s2, None, s1]
    assert path[1].sidesite is side and path[0].sidesite is None
    assert path[3].divisor == 2.0 and path[0].divisor is None
    assert fixed.path[0] is joint_wrap
    assert joint_wrap.target is joint and joint_wrap.coef == 3.0
    with pytest.raises(IndexError):
        path[5]
    with pytest.raises(TypeError):
        path["0"]
    spatial.wrap_site("s2")
    assert len(path) == 6          # read live
    assert spatial.default().name == "main"


# ---------------------------------------------------- common element properties

def test_signature_follows_compiles(mujoco):
    for module in (mjcffi, mujoco):
        spec = module.MjSpec()
        body = spec.worldbody.add_body()
        body.add_geom(size=[1, 0, 0])
        assert body.signature == 0
        model = spec.compile()
        assert body.signature == model.signature != 0
        geom = body.add_geom(size=[1, 0, 0])
        assert geom.signature == body.signature == 0
        model = spec.compile()
        assert geom.signature == model.signature


def test_id_classname_and_compiler(mujoco):
    xml = """<mujoco><default><default class="c"><geom size=".1"/></default></default>
      <worldbody><body name="a" childclass="c"><geom name="g"/></body></worldbody></mujoco>"""
    spec, official = MjSpec.from_string(xml), mujoco.MjSpec.from_string(xml)
    geom = spec.geom("g")
    assert geom.id == -1
    spec.compile()
    official.compile()
    assert geom.id == official.geom("g").id == 0
    assert spec.body("a").id == official.body("a").id == 1
    assert geom.classname.name == official.geom("g").classname.name == "c"
    assert spec.body("a").classname.name == official.body("a").classname.name
    main = spec.worldbody.classname
    assert main.name == official.worldbody.classname.name == "main"
    geom.classname = main
    assert geom.classname is main
    with pytest.raises(TypeError, match="MjsDefault"):
        geom.classname = "c"
    with pytest.raises(ValueError, match="another spec"):
        geom.classname = MjSpec.from_string(xml).geom("g").classname
    assert geom.compiler.degree == official.geom("g").compiler.degree
    assert geom.compiler.autolimits == spec.compiler.autolimits


def test_read_only_properties():
    spec = MjSpec.from_string(TREE)
    body = spec.body("a")
    for name, value in (("parent", None), ("signature", 1), ("id", 3),
                        ("bodies", []), ("frame", None)):
        with pytest.raises(AttributeError):
            setattr(body, name, value)


def test_wrappers_are_of_the_subclasses():
    from mjcffi.spec import elements
    spec = MjSpec.from_string(TREE)
    assert type(spec.body("a")) is elements.MjsBody
    assert type(spec.geom("g1")) is elements.MjsGeom
    assert type(spec.worldbody.add_site()) is elements.MjsSite
    assert isinstance(spec.body("a"), mjcffi.MjsBody)


def test_public_methods_have_docstrings():
    from mjcffi.spec import elements
    checked = 0
    for cls in elements.CLASSES + (elements.MjsTendonPath,):
        assert (cls.__doc__ or "").strip(), cls.__name__
        for base in cls.__mro__:
            if base.__module__ != elements.__name__:
                continue
            for name, member in vars(base).items():
                if not name.startswith("_") and (callable(member) or
                                                 isinstance(member, property)):
                    assert (member.__doc__ or "").strip(), f"{base.__name__}.{name}"
                    checked += 1
    assert checked > 50


def test_attached_body_is_found_from_the_parent_once_its_spec_is_gone():
    parent = MjSpec()
    frame = parent.worldbody.add_frame()
    child, body = child_spec()
    frame.attach_body(body, "c-")
    del child
    gc.collect()
    assert parent.body("c-b") is body
    assert names(parent.worldbody.find_all("body")) == ["c-b"]


# ---------------------------------------------------------------- actuators

SHORTCUTS = [
    ("set_to_motor", {}),
    ("set_to_position", {"kp": 2.0, "kv": 3.0, "timeconst": 4.0, "inheritrange": True}),
    ("set_to_position", {"kp": 5.0, "dampratio": 0.7}),
    ("set_to_intvelocity", {"kp": 2.0, "kv": 3.0, "timeconst": 4.0}),
    ("set_to_velocity", {"kv": 5.0}),
    ("set_to_orientation", {"kp": 2.0, "dampratio": 1.0}),
    ("set_to_pid", {"kp": 2.0, "kv": 3.0, "ki": 0.5, "imax": 1.5, "slewmax": 4.0}),
    ("set_to_damper", {"kv": 6.0}),
    ("set_to_cylinder", {"timeconst": 0.1, "bias": 2.0, "area": 0.5}),
    ("set_to_cylinder", {"timeconst": 0.1, "bias": 2.0, "area": -1, "diameter": 0.3}),
    ("set_to_muscle", {"tausmooth": 0.1}),
    ("set_to_muscle", {"timeconst": [0.02, 0.05], "tausmooth": 0.2, "range": [0.8, 1.2],
                       "force": 5.0, "scale": 250.0, "lmin": 0.6, "lmax": 1.7, "vmax": 1.8,
                       "fpmax": 1.4, "fvmax": 1.5}),
    ("set_to_adhesion", {"gain": 7.0}),
    ("set_to_dcmotor", {"motorconst": [0.05, 0.05], "resistance": 2.0}),
    ("set_to_dcmotor", {"motorconst": [0.05, 0.04], "resistance": 2.0,
                        "inductance": [0.001, 0.0], "thermal": [1, 2, 3, 4, 5, 6]}),
]
ACTUATOR_FIELDS = ("gaintype", "gainprm", "biastype", "biasprm", "dyntype", "dynprm",
                   "inheritrange", "actdim", "ctrlspec", "actlimited", "actrange")


@pytest.mark.parametrize("method, kwargs", SHORTCUTS, ids=[m for m, _ in SHORTCUTS])
def test_actuator_shortcuts_match_official(method, kwargs, mujoco):
    actuators = []
    for module in (mjcffi, mujoco):
        actuator = module.MjSpec().add_actuator(dyntype=module.mjtDyn.mjDYN_FILTER)
        assert getattr(actuator, method)(**kwargs) is None
        actuators.append(actuator)
    for field in ACTUATOR_FIELDS:
        ours, theirs = (getattr(a, field) for a in actuators)
        np.testing.assert_array_equal(np.asarray(ours), np.asarray(theirs), field)


def test_actuator_shortcut_refusals(mujoco):
    actuator = MjSpec().add_actuator()
    official = mujoco.MjSpec().add_actuator()
    with pytest.raises(ValueError) as ours:
        actuator.set_to_position(kp=1, kv=1, dampratio=1)
    with pytest.raises(ValueError) as theirs:
        official.set_to_position(kp=1, kv=1, dampratio=1)
    assert str(theirs.value) in str(ours.value)
    with pytest.raises(TypeError, match="tausmooth is required"):
        actuator.set_to_muscle()
    with pytest.raises(ValueError, match="motorconst must have 2 elements"):
        actuator.set_to_dcmotor(motorconst=[1, 2, 3], resistance=1)
    with pytest.raises(TypeError, match="kp must be a number"):
        actuator.set_to_position(kp="stiff")

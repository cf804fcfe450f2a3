"""mujoco-py's modders (mjcffi.sim.modder): TextureModder, MaterialModder, LightModder,
CameraModder.

What needs no OpenGL (the model fields each setter writes, the random state, the
bad input) runs here.  What is drawn runs in a subprocess per backend (EGL and
OSMesa; see tests/_gl.py), which prints one JSON line of what it saw: each edit
changes the pixels, and undoing it (the original model values, the original
texture bytes uploaded again) gives the first image back bit for bit.
"""

import functools
import os

import numpy as np
import pytest
from tests import _gl

BACKENDS = ("egl", "osmesa")
W, H = 96, 80

# four textured boxes under a named light, seen from above by a named camera; a fifth,
# plain box stands on a plane below so that the light casts a shadow
SCENE = """
<mujoco>
  <asset>
    <texture name="t1" type="2d" builtin="flat" width="33" height="36" rgb1=".8 .8 .8"/>
    <texture name="t2" type="2d" builtin="checker" width="34" height="39"
             rgb1=".9 .2 .2" rgb2=".2 .3 .9"/>
    <texture name="t3" type="2d" builtin="gradient" width="31" height="37"/>
    <texture name="sky" type="skybox" builtin="flat" width="16" height="16" rgb1=".3 .4 .5"/>
    <material name="m1" texture="t1"/>
    <material name="m2" texture="t2"/>
    <material name="m3" texture="t3"/>
    <material name="m4" texture="t1" rgba=".5 .9 .5 1"/>
  </asset>
  <worldbody>
    <light name="lamp" pos="0.3 0.2 3" dir="0 0 -1" diffuse=".7 .7 .7" castshadow="true"/>
    <light name="fill" pos="0 0 4" dir="0 0 -1" diffuse=".1 .1 .1" castshadow="false"/>
    <camera name="top" pos="0 0 3"/>
    <geom name="floor" type="plane" size="3 3 0.1" rgba=".9 .9 .9 1"/>
    <geom name="g1" pos="-0.5 0.5 0.1" type="box" size="0.4 0.4 0.1" material="m1"/>
    <geom name="g2" pos="0.5 0.5 0.1" type="box" size="0.4 0.4 0.1" material="m2"/>
    <geom name="g3" pos="0.5 -0.5 0.1" type="box" size="0.4 0.4 0.1" material="m3"/>
    <geom name="g4" pos="-0.5 -0.5 0.1" type="box" size="0.4 0.4 0.1" material="m4"/>
    <geom name="pillar" pos="0 0 1" type="box" size="0.1 0.1 0.1" rgba="1 1 0 1"/>
  </worldbody>
</mujoco>
"""


def _sim(xml=SCENE):
    from mjcffi.sim import MjSim, load_model_from_xml
    sim = MjSim(load_model_from_xml(xml))
    sim.forward()
    return sim


def _humanoid():
    import gymnasium
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                        "humanoid.xml")


# ------------------------------------------------------------ the module

def test_the_mujoco_py_path_exports_the_four_modders():
    import mjcffi.sim
    from mjcffi.sim import modder
    for name in ("TextureModder", "MaterialModder", "LightModder", "CameraModder"):
        assert isinstance(getattr(modder, name), type)
        assert name in modder.__all__
    assert mjcffi.sim.TextureModder is modder.TextureModder
    assert mjcffi.sim.MaterialModder is modder.MaterialModder


def test_a_modder_needs_an_mjsim():
    import mjcffi
    from mjcffi.sim.modder import LightModder
    model = mjcffi.MjModel.from_xml_string(SCENE)
    with pytest.raises(TypeError, match="sim must be an MjSim, not MjModel"):
        LightModder(model)


# ------------------------------------------------------------ random_state

def _randomized(random_state):
    """The texture bytes and material values after randomizing with `random_state()`."""
    from mjcffi.sim.modder import MaterialModder, TextureModder
    sim = _sim()
    textures = TextureModder(sim, random_state=random_state())
    textures.randomize()
    MaterialModder(sim, random_state=random_state()).randomize()
    model = sim.model
    return model.tex_data.copy(), np.concatenate([model.mat_specular, model.mat_shininess,
                                                   model.mat_reflectance])


def test_a_seed_makes_the_randomization_reproducible():
    first_tex, first_mat = _randomized(lambda: 5)
    again_tex, again_mat = _randomized(lambda: np.int64(5))
    state_tex, state_mat = _randomized(lambda: np.random.RandomState(5))
    other_tex, other_mat = _randomized(lambda: 6)
    assert np.array_equal(first_tex, again_tex) and np.array_equal(first_mat, again_mat)
    assert np.array_equal(first_tex, state_tex) and np.array_equal(first_mat, state_mat)
    assert not np.array_equal(first_tex, other_tex)
    assert not np.array_equal(first_mat, other_mat)
    assert not np.array_equal(first_tex, _sim().model.tex_data)


def test_a_shared_random_state_is_drawn_from_in_turn():
    from mjcffi.sim.modder import TextureModder
    state = np.random.RandomState(0)
    first = TextureModder(_sim(), random_state=state).rand_rgb("g1").copy()
    second = TextureModder(_sim(), random_state=state).rand_rgb("g1").copy()
    expected = np.random.RandomState(0)
    assert first[0, 0].tolist() == (expected.uniform(size=3) * 255).astype(np.uint8).tolist()
    assert second[0, 0].tolist() == (expected.uniform(size=3) * 255).astype(np.uint8).tolist()


def test_random_state_none_is_a_fresh_state_and_other_kinds_are_refused():
    from mjcffi.sim.modder import CameraModder
    sim = _sim()
    state = CameraModder(sim).random_state
    assert isinstance(state, np.random.RandomState) and state is not np.random.mtrand._rand
    for bad in (1.5, "7", True, np.random.default_rng(0)):
        with pytest.raises(TypeError, match="random_state must be None, a seed or a numpy"):
            CameraModder(sim, random_state=bad)


# ------------------------------------------------------------ textures, no OpenGL

def test_checker_and_gradient_draw_what_mujoco_py_drew():
    """mujoco-py put rgb2 at the first pixel of a checkerboard and truncated blended
    colours to bytes; seeded runs draw the same pixels only if both hold."""
    from mjcffi.sim.modder import TextureModder
    sim = _sim()
    textures = TextureModder(sim)
    checker = textures.set_checker("g1", (255, 0, 0), (0, 0, 255))
    assert checker.shape == (36, 33, 3)
    assert checker[0, 0].tolist() == [0, 0, 255] and checker[0, 1].tolist() == [255, 0, 0]
    assert checker[1, 0].tolist() == [255, 0, 0] and checker[35, 32].tolist() == [255, 0, 0]
    odd, even = textures.get_checker_matrices("g1")
    assert odd.shape == even.shape == (36, 33, 1) and np.all(odd + even == 1)
    gradient = textures.set_gradient("g3", (0, 0, 0), (255, 100, 10), vertical=False)
    p = np.linspace(0, 1, 31)
    assert gradient[7, :, 0].tolist() == np.trunc(255 * p).astype(int).tolist()
    assert gradient[7, :, 1].tolist() == np.trunc(100 * p).astype(int).tolist()
    vertical = textures.set_gradient("g3", (200, 0, 0), (0, 0, 0), vertical=True)
    assert vertical[:, 3, 0].tolist() == np.trunc(200 * (1 - np.linspace(0, 1, 37))).astype(
        int).tolist()
    assert textures.set_rgb("g1", (10.9, 20, 30))[5, 5].tolist() == [10, 20, 30]


def test_texture_edits_are_live_views_of_the_model_shared_by_its_geoms():
    from mjcffi.sim.modder import TextureModder
    sim = _sim()
    textures = TextureModder(sim, random_state=1)
    texture = textures.get_texture("g4")
    assert texture is textures.get_texture("g1")          # m1 and m4 share t1
    assert (texture.type, texture.width, texture.height) == ("2d", 33, 36)
    bitmap = textures.set_noise("g4", (0, 0, 0), (255, 255, 255), fraction=0.25)
    block = sim.model.tex_data[texture.tex_adr:texture.tex_adr + 33 * 36 * 3]
    assert np.array_equal(block.reshape(36, 33, 3), bitmap)
    assert 0.15 < float(np.mean(bitmap[..., 0] == 255)) < 0.35
    assert textures.get_texture("skybox").type == "skybox"
    before = sim.model.mat_rgba.copy()
    textures.whiten_materials(["g4"])
    assert sim.model.mat_rgba[3].tolist() == [1, 1, 1, 1]
    assert np.array_equal(sim.model.mat_rgba[:3], before[:3])
    textures.whiten_materials()
    assert np.all(sim.model.mat_rgba == 1)


def test_randomize_draws_every_textured_geom_of_a_real_model():
    from mjcffi.sim import MjSim, load_model_from_path
    from mjcffi.sim.modder import TextureModder
    sim = MjSim(load_model_from_path(_humanoid()))
    original = sim.model.tex_data.copy()
    textures = TextureModder(sim, random_state=2)
    sky = textures.get_texture("skybox")
    sky_bytes = sky.bitmap.copy()
    textures.randomize()
    floor = textures.get_texture("floor")
    assert not np.array_equal(floor.bitmap, original[floor.tex_adr:][:100 * 100 * 3]
                              .reshape(100, 100, 3))
    assert not np.array_equal(sky.bitmap, sky_bytes)
    textures.rand_rgb("skybox")
    assert len(np.unique(sky.bitmap.reshape(-1, 3), axis=0)) == 1


# ------------------------------------------------------------ lights and cameras, no OpenGL

def test_the_light_modder_writes_the_named_light():
    from mjcffi.sim.modder import LightModder
    sim = _sim()
    model, lights = sim.model, LightModder(sim)
    lamp = lights.get_lightid("lamp")
    assert lamp == model.light("lamp").id and lights.get_lightid("fill") != lamp
    lights.set_pos("lamp", [1, 2, 3])
    lights.set_dir("lamp", np.array([0, 1, -1], np.float32))
    lights.set_specular("lamp", (0.1, 0.2, 0.3))
    lights.set_ambient("lamp", (0.4, 0.5, 0.6))
    lights.set_diffuse("lamp", (0.7, 0.8, 0.9))
    lights.set_active("lamp", 0)
    lights.set_castshadow("lamp", False)
    assert model.light_pos[lamp].tolist() == [1, 2, 3]
    assert model.light_dir[lamp].tolist() == [0, 1, -1]
    assert model.light_specular[lamp].tolist() == pytest.approx([0.1, 0.2, 0.3])
    assert model.light_ambient[lamp].tolist() == pytest.approx([0.4, 0.5, 0.6])
    assert model.light_diffuse[lamp].tolist() == pytest.approx([0.7, 0.8, 0.9])
    assert not model.light_active[lamp] and not model.light_castshadow[lamp]
    fill = model.light("fill").id
    assert model.light_active[fill] and model.light_pos[fill].tolist() == [0, 0, 4]
    sim.forward()                                       # the world frame follows
    assert sim.data.light_xpos[lamp].tolist() == [1, 2, 3]
    lights.set_active("lamp", True)
    assert model.light_active[lamp]


def test_the_camera_modder_gets_and_sets_the_named_camera():
    from mjcffi.sim.modder import CameraModder
    sim = _sim()
    model, cameras = sim.model, CameraModder(sim)
    assert cameras.get_camid("top") == model.camera("top").id
    pos = cameras.get_pos("top")
    assert pos.tolist() == [0, 0, 3] and cameras.get_quat("top").tolist() == [1, 0, 0, 0]
    cameras.set_pos("top", (0.5, 0, 2))
    assert pos.tolist() == [0.5, 0, 2]                     # get_pos is a live view
    half = np.sqrt(0.5)
    cameras.set_quat("top", [half, 0, 0, half])
    cameras.set_fovy("top", 30)
    assert model.cam_quat[0].tolist() == pytest.approx([half, 0, 0, half])
    assert model.cam_fovy[0] == 30
    sim.forward()
    assert sim.data.cam_xpos[0].tolist() == [0.5, 0, 2]
    assert sim.data.cam_xmat[0].reshape(3, 3)[:, 0] == pytest.approx([0, 1, 0])


# ------------------------------------------------------------ bad input

def _refusals():
    from mjcffi.sim.modder import CameraModder, LightModder, MaterialModder, TextureModder
    sim = _sim()
    lights, cameras = LightModder(sim), CameraModder(sim)
    textures, materials = TextureModder(sim), MaterialModder(sim)
    return sim, [
        (lambda: lights.set_pos("lantern", (0, 0, 1)), ValueError,
         "the model has no light named 'lantern'"),
        (lambda: lights.get_lightid(""), ValueError, "the model has no light named ''"),
        (lambda: lights.set_diffuse(3, (0, 0, 1)), TypeError, "a light name must be a str"),
        (lambda: lights.set_pos("lamp", (0, 1)), ValueError,
         r"light pos must be 3 numbers \(shape \(3,\)\), not an array of shape \(2,\)"),
        (lambda: lights.set_ambient("lamp", np.ones((1, 3))), ValueError,
         r"ambient must be 3 numbers .*shape \(1, 3\)"),
        (lambda: lights.set_specular("lamp", "abc"), TypeError, "specular must be 3 numbers"),
        (lambda: lights.set_diffuse("lamp", (0, np.nan, 1)), ValueError,
         "diffuse must be finite"),
        (lambda: lights.set_dir("lamp", (0, 0, 0)), ValueError,
         "light dir must not be all zeros"),
        (lambda: lights.set_active("lamp", 2), ValueError,
         "active must be True, False, 1 or 0, not 2"),
        (lambda: lights.set_castshadow("lamp", "yes"), ValueError, "castshadow must be True"),
        (lambda: cameras.set_pos("side", (0, 0, 1)), ValueError,
         "the model has no camera named 'side'"),
        (lambda: cameras.get_quat("lamp"), ValueError, "the model has no camera named 'lamp'"),
        (lambda: cameras.set_quat("top", (1, 0, 0)), ValueError,
         r"camera quat must be 4 numbers \(shape \(4,\)\)"),
        (lambda: cameras.set_quat("top", (0, 0, 0, 0)), ValueError,
         "camera quat must not be all zeros"),
        (lambda: cameras.set_fovy("top", 180), ValueError,
         "fovy must be between 0 and 180 degrees, not 180.0"),
        (lambda: cameras.set_fovy("top", "45"), TypeError, "fovy must be a number, not str"),
        (lambda: cameras.set_fovy("top", float("inf")), ValueError, "fovy must be finite"),
        (lambda: textures.set_rgb("g9", (1, 2, 3)), ValueError,
         "the model has no geom named 'g9'"),
        (lambda: textures.set_checker("g1", (1, 2), (3, 4, 5)), ValueError,
         "rgb1 must be three numbers from 0 to 255"),
        (lambda: textures.set_noise("g1", (0, 0, 0), (1, 1, 1), fraction=2), ValueError,
         "fraction must be from 0 to 1, not 2.0"),
        (lambda: textures.whiten_materials(["g1", "floor"]), ValueError,
         "geom 'floor' has no material"),
        (lambda: textures.get_texture("pillar"), ValueError, "geom 'pillar' has no material"),
        (lambda: materials.set_specularity("g1", -0.1), ValueError,
         "specularity must be from 0 to 1"),
        (lambda: materials.set_rgba("g1", (1, 1, 1)), ValueError, "rgba must be 4 numbers"),
        (lambda: materials.set_texrepeat("g1", "2", 2), TypeError,
         "repeat_x must be a number, not str"),
        (lambda: materials.rand_texrepeat("g1", 0), ValueError, "max_repeat must be at least 1"),
    ]


def test_bad_input_is_refused_with_its_name_and_leaves_the_model_alone():
    sim, refusals = _refusals()
    model = sim.model
    fields = ("light_pos", "light_dir", "light_ambient", "light_diffuse", "light_specular",
              "light_active", "light_castshadow", "cam_pos", "cam_quat", "cam_fovy",
              "mat_rgba", "mat_specular", "mat_texrepeat", "tex_data")
    before = {f: getattr(model, f).copy() for f in fields}
    for call, kind, message in refusals:
        with pytest.raises(kind, match=message):
            call()
    for field in fields:
        assert np.array_equal(getattr(model, field), before[field]), field


# ------------------------------------------------------------ what is drawn

def render_scenario():
    """Every edit, rendered: does it change the image, and does undoing it give the
    first image back exactly?  One JSON line."""
    import json

    from mjcffi.sim.modder import CameraModder, LightModder, MaterialModder, TextureModder
    sim = _sim()
    model = sim.model

    def frame():
        return sim.render(W, H, camera_name="top")

    def changed(image):
        return int(np.count_nonzero(np.any(image != base, axis=2)))

    base = frame()
    out = {"lit": float(base.mean())}

    # textures: randomize every textured geom and the skybox, then upload the original bytes
    original = model.tex_data.copy()
    textures = TextureModder(sim, random_state=11)
    textures.randomize()
    randomized = frame()
    out["texture_changes"] = changed(randomized)
    model.tex_data[:] = original
    for name in ("g1", "g2", "g3", "skybox"):
        textures.upload_texture(name)
    out["texture_restored"] = bool(np.array_equal(frame(), base))
    # the same seed on a second sim: the same picture
    other = _sim()
    TextureModder(other, random_state=11).randomize()
    out["texture_reproduced"] = bool(np.array_equal(
        other.render(W, H, camera_name="top"), randomized))
    # an edit uploaded to a render context made before it, a second one included
    from mjcffi.sim import MjRenderContextOffscreen
    second = MjRenderContextOffscreen(sim)
    textures.set_checker("g2", (255, 255, 0), (0, 0, 0))
    second.render(W, H, camera_id=model.camera("top").id)
    out["second_context"] = bool(np.array_equal(second.read_pixels(W, H, depth=False),
                                                 frame()))
    model.tex_data[:] = original
    textures.upload_texture("g2")

    # materials: one change, then the original values back
    materials = MaterialModder(sim, random_state=3)
    saved = model.mat_texrepeat.copy(), model.mat_texuniform.copy()
    materials.rand_texrepeat("g2", max_repeat=4)
    if np.array_equal(model.mat_texrepeat, saved[0]):      # drew the same repeats
        materials.set_texrepeat("g2", 3, 2)
    out["material_changes"] = changed(frame())
    model.mat_texrepeat[:], model.mat_texuniform[:] = saved
    out["material_restored"] = bool(np.array_equal(frame(), base))

    # lights: each edit alone, then the original values (and mj_forward) back
    lights = LightModder(sim, random_state=0)
    lamp = lights.get_lightid("lamp")
    edits = {
        "diffuse": lambda: lights.set_diffuse("lamp", (0, 0, 0)),
        "ambient": lambda: lights.set_ambient("lamp", (0.4, 0.4, 0.4)),
        "specular": lambda: lights.set_specular("lamp", (1, 1, 1)),
        "active": lambda: lights.set_active("lamp", False),
        "castshadow": lambda: lights.set_castshadow("lamp", False),
        "pos": lambda: lights.set_pos("lamp", (-1.5, -1, 2)),
        "dir": lambda: lights.set_dir("lamp", (0.6, 0, -1)),
    }
    fields = ("light_pos", "light_dir", "light_diffuse", "light_ambient", "light_specular",
              "light_active", "light_castshadow")
    out["light"] = {}
    for name, edit in edits.items():
        kept = {f: getattr(model, f)[lamp].copy() for f in fields}
        edit()
        sim.forward()
        image = frame()
        for f in fields:
            getattr(model, f)[lamp] = kept[f]
        sim.forward()
        out["light"][name] = [changed(image), float(image.mean()),
                              bool(np.array_equal(frame(), base))]

    # cameras: each edit alone, then the original values back
    cameras = CameraModder(sim)
    top = cameras.get_camid("top")
    half = float(np.sqrt(0.5))
    edits = {
        "fovy": lambda: cameras.set_fovy("top", 25),
        "pos": lambda: cameras.set_pos("top", (0.4, 0, 3)),
        "quat": lambda: cameras.set_quat("top", (half, 0, 0, half)),
    }
    out["camera"] = {}
    for name, edit in edits.items():
        kept = [model.cam_pos[top].copy(), model.cam_quat[top].copy(),
                float(model.cam_fovy[top])]
        edit()
        sim.forward()
        image = frame()
        model.cam_pos[top], model.cam_quat[top], model.cam_fovy[top] = kept
        sim.forward()
        out["camera"][name] = [changed(image), bool(np.array_equal(frame(), base))]
    print(json.dumps(out))


@functools.lru_cache(maxsize=None)
def _rendered(backend):
    return _gl.run("tests.test_sim_modder", backend, "render_scenario")


@pytest.fixture(params=BACKENDS)
def rendered(request):
    reason = _gl.skip_reason(request.param)
    if reason:
        pytest.skip(reason)
    return _rendered(request.param)


def test_a_randomized_texture_is_drawn_and_the_original_bytes_restore_the_image(rendered):
    assert rendered["lit"] > 20
    assert rendered["texture_changes"] > W * H // 10
    assert rendered["texture_restored"]
    assert rendered["texture_reproduced"]
    assert rendered["second_context"]


def test_a_material_edit_is_drawn_and_undone(rendered):
    assert rendered["material_changes"] > 100
    assert rendered["material_restored"]


@pytest.mark.parametrize("edit", ["diffuse", "ambient", "specular", "active", "castshadow",
                                  "pos", "dir"])
def test_each_light_edit_is_drawn_and_undone(rendered, edit):
    changes, mean, restored = rendered["light"][edit]
    assert changes > 20, edit
    assert restored, edit
    if edit in ("diffuse", "active"):                    # less light: a darker picture
        assert mean < rendered["lit"] - 5
    if edit == "ambient":
        assert mean > rendered["lit"] + 5


@pytest.mark.parametrize("edit", ["fovy", "pos", "quat"])
def test_each_camera_edit_is_drawn_and_undone(rendered, edit):
    changes, restored = rendered["camera"][edit]
    assert changes > W * H // 20, edit
    assert restored, edit

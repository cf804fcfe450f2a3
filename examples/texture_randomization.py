"""Texture and material randomization with mjcffi's mujoco-py interface, headless.

Each frame gives every textured geom (and the sky) a new random texture
(flat colour, checkerboard, gradient or noise) and every material a new
specularity, shininess and reflectance, steps the physics, and renders the
scene from a fixed camera offscreen: the kind of images used to train vision
models that must not rely on colours and textures (domain randomization).

    python examples/texture_randomization.py --frames 20
    python examples/texture_randomization.py --frames 50 --out /tmp/frames   # PNG files

MUJOCO_GL picks the OpenGL backend (egl or osmesa without a display).
"""

import argparse
import os
import struct
import sys
import time
import zlib

from mjcffi.sim import MaterialModder, MjSim, TextureModder, load_model_from_xml

SCENE = """
<mujoco model="texture randomization">
  <visual><global offwidth="640" offheight="480"/></visual>
  <asset>
    <texture name="sky" type="skybox" builtin="gradient" width="64" height="64"
             rgb1="0.4 0.6 0.8" rgb2="0 0 0"/>
    <texture name="floor" type="2d" builtin="checker" width="64" height="64"
             rgb1="0.2 0.3 0.4" rgb2="0.1 0.2 0.3"/>
    <texture name="box" type="cube" builtin="flat" width="32" height="32" rgb1="0.8 0.4 0.1"/>
    <texture name="ball" type="2d" builtin="gradient" width="32" height="32"
             rgb1="0.9 0.9 0.2" rgb2="0.2 0.6 0.2"/>
    <material name="floor" texture="floor" texrepeat="4 4"/>
    <material name="box" texture="box"/>
    <material name="ball" texture="ball"/>
  </asset>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1" diffuse="0.8 0.8 0.8"/>
    <camera name="front" pos="0 -1.6 0.9" xyaxes="1 0 0 0 0.5 1"/>
    <geom name="floor" type="plane" size="2 2 0.1" material="floor"/>
    <body name="box" pos="-0.3 0 0.3">
      <freejoint/>
      <geom name="box" type="box" size="0.15 0.15 0.15" material="box"/>
    </body>
    <body name="ball" pos="0.3 0.1 0.5">
      <freejoint/>
      <geom name="ball" type="sphere" size="0.15" material="ball"/>
    </body>
  </worldbody>
</mujoco>
"""


def write_png(path, rgb):
    """Save a (height, width, 3) uint8 image, top row first, as a PNG file."""
    height, width, _ = rgb.shape
    rows = b"".join(b"\x00" + rgb[y].tobytes() for y in range(height))   # filter 0 per row

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + \
            struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(rows)))
        f.write(chunk(b"IEND", b""))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20, help="frames to render (20)")
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=120)
    parser.add_argument("--seed", type=int, default=0, help="random seed (0)")
    parser.add_argument("--out", help="folder to save the frames in as PNG files")
    args = parser.parse_args(argv)
    if args.frames < 1:
        parser.error("--frames must be at least 1")

    sim = MjSim(load_model_from_xml(SCENE), nsubsteps=10)
    textures = TextureModder(sim, random_state=args.seed)
    materials = MaterialModder(sim, random_state=args.seed + 1)
    textures.whiten_materials()          # let the textures show their own colours
    if args.out:
        os.makedirs(args.out, exist_ok=True)

    seen = set()
    start = time.perf_counter()
    for frame in range(args.frames):
        textures.randomize()             # new pixels, uploaded to the render contexts
        materials.randomize()            # read by MuJoCo at the next frame
        sim.step()
        rgb = sim.render(args.width, args.height, camera_name="front")
        picture = rgb[::-1]              # OpenGL gives the bottom row first
        seen.add(hash(picture.tobytes()))
        if args.out:
            write_png(os.path.join(args.out, f"frame_{frame:04d}.png"), picture)
    elapsed = time.perf_counter() - start

    print(f"{args.frames} frames of {args.width}x{args.height}, {len(seen)} distinct, "
          f"{args.frames / elapsed:.1f} frames/s"
          + (f", saved in {args.out}" if args.out else ""))
    return 0 if len(seen) == args.frames else 1


if __name__ == "__main__":
    sys.exit(main())

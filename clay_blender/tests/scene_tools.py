"""Headless Blender helpers shared by the add-on's test and the docs picture: a fresh file
with the add-on registered, the castle imported, and a render of it."""

import math
import sys
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import clay_blender  # noqa: E402  (the repository's add-on folder)

CASTLE = ROOT / "grammars" / "castle.clay"
CASTLE_SCRIPT = ROOT / "grammars" / "castle.script.json"
#: The docs picture `picture.py` makes and `test_blender.py` checks.
PICTURE = ROOT / "docs" / "pictures" / "blender-castle.png"
PICTURE_SIZE = (800, 500)


def fresh_file():
    """An empty scene with the add-on registered (once)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if not hasattr(bpy.types, "CLAY_OT_import_grammar"):
        clay_blender.register()


def unregister():
    """Unregisters the add-on if it is registered: the `bpy` module (4.2) crashes at the
    interpreter's exit while an add-on class or menu entry is still registered."""
    if hasattr(bpy.types, "CLAY_OT_import_grammar"):
        clay_blender.unregister()


def bounds(objects):
    """The world-space bounding box of `objects`' vertices: (min xyz, max xyz)."""
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for obj in objects:
        for v in obj.data.vertices:
            w = obj.matrix_world @ v.co
            for k in range(3):
                lo[k] = min(lo[k], w[k])
                hi[k] = max(hi[k], w[k])
    return lo, hi


def render(path, size):
    """Renders the scene with Workbench from a camera above the south, into a PNG of `size`
    pixels."""
    scene = bpy.context.scene
    objects = [o for o in scene.objects if o.type == "MESH"]
    lo, hi = bounds(objects)
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    extent = max(hi[0] - lo[0], hi[1] - lo[1], 1.0)

    cam_data = bpy.data.cameras.new("clay camera")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = extent * 1.6
    cam = bpy.data.objects.new("clay camera", cam_data)
    scene.collection.objects.link(cam)
    # Looking down at 50 degrees from the south-south-west.
    tilt, turn = math.radians(50), math.radians(-25)
    distance = extent * 3
    cam.location = (
        centre[0] + distance * math.sin(turn) * math.cos(tilt) * -1,
        centre[1] - distance * math.cos(turn) * math.cos(tilt),
        centre[2] + distance * math.sin(tilt),
    )
    direction = [centre[k] - cam.location[k] for k in range(3)]
    import mathutils

    cam.rotation_euler = mathutils.Vector(direction).to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam

    # Workbench: Blender's rasteriser, which runs headless on software OpenGL (EGL). A ray
    # tracer would shade the coplanar tops of overlapping pieces (a wall's end on a tower)
    # black; a depth buffer shows one of them.
    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.color_type = "MATERIAL"
    shading.show_shadows = True
    shading.shadow_intensity = 0.4
    shading.show_cavity = True
    shading.cavity_type = "WORLD"
    scene.display.render_aa = "8"
    scene.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("clay background")
    world.color = (0.92, 0.9, 0.86)
    scene.world = world
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)

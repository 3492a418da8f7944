"""Makes docs/pictures/blender-castle.png: the castle after its demo script, imported by the
add-on into a headless Blender and rendered with Workbench. Run it with the Python that has
`bpy` and `clay` installed (docs/blender.md):

    python clay_blender/tests/picture.py

`test_blender.py` checks that the picture is there at its size.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

from scene_tools import (  # noqa: E402
    CASTLE,
    CASTLE_SCRIPT,
    PICTURE,
    PICTURE_SIZE,
    ROOT,
    fresh_file,
    render,
    unregister,
)


def main():
    fresh_file()
    bpy.ops.clay.import_grammar(filepath=str(CASTLE), script=str(CASTLE_SCRIPT))
    render(PICTURE, PICTURE_SIZE)
    unregister()
    print(f"wrote {PICTURE.relative_to(ROOT)}")


if __name__ == "__main__":
    main()

"""Clay grammars in Blender: File > Import > Clay grammar (.clay).

A grammar (and, optionally, a sculpting script) is imported as one collection: a root Empty
named after the grammar and under it an object per instance at its own pivot (the instance's
centroid), turned as its rest state is, named as in ``clayc export``'s glTF (``wall_n_4``, the
fifth brick of chain ``wall_n``) with the properties Blender's glTF importer gives from its
extras (``instance``, ``piece``, ``state``, ``id``, ``chain``, ``index``); identical instances
share one mesh with a planar ``UVMap``, one material per fill colour named as in every export
(``fill_9a958cff``), heights as ``clayc export`` gives them (metres, z up). The grammar's
parameters become properties of the collection (Properties > Collection > Clay).

Reload (and a parameter change) updates the collection in place: an instance that is still
there keeps its object, with the user's modifiers, object materials, children and properties;
new instances are added, gone ones removed (their children stay, under the root); objects Clay
did not make are never touched. Paths are stored relative to the .blend once it is saved.

The meshes come from the Python package ``clay`` (docs/python.md), which must be importable
by Blender's Python: docs/blender.md says how to install it.
"""

bl_info = {
    "name": "Clay grammars",
    "author": "Clay",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "File > Import > Clay grammar (.clay); Properties > Collection > Clay",
    "description": "Import a Clay structured-shape grammar, sculpted by a script, as a collection",
    "category": "Import-Export",
}

import json
import os

import bpy
from bpy.props import FloatProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

# Custom properties the add-on keeps on a collection it made.
PATH = "clay_path"
SCRIPT = "clay_script"
THICKNESS = "clay_thickness"
PARAMS = "clay_params"
# Custom properties on what the add-on made: an object's export node name (its identity across
# reloads), the root Empty's mark, a mesh's export mesh name.
NODE = "clay_node"
ROOT = "clay_root"
MESH = "clay_mesh"

DEFAULT_THICKNESS = 0.05


def _clay():
    """The clay package, or an ImportError that says how to get it."""
    try:
        import clay
    except ImportError as e:  # pragma: no cover - depends on the installation
        raise ImportError(
            "the Python package `clay` is not installed in Blender's Python: "
            "see docs/blender.md (pip install the clay-sculpt wheel with Blender's python)"
        ) from e
    return clay


def srgb_to_linear(c):
    """A colour byte (sRGB) as Blender's linear float, as glTF's importer does."""
    c = c / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def material_for(prim):
    """The material of a primitive's fill colour, made once per file and named as every export
    names it (``prim.material``, ``fill_9a958cff``)."""
    r, g, b, a = prim.colour
    name = prim.material
    mat = bpy.data.materials.get(name)
    if mat is not None:
        return mat
    mat = bpy.data.materials.new(name)
    linear = (srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b), a / 255.0)
    mat.diffuse_color = linear
    mat.roughness = 0.9
    mat.metallic = 0.0
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    if bsdf is not None:
        bsdf.inputs["Base Color"].default_value = linear
        bsdf.inputs["Alpha"].default_value = linear[3]
        bsdf.inputs["Roughness"].default_value = 0.9
        bsdf.inputs["Metallic"].default_value = 0.0
    if a < 255:
        mat.surface_render_method = "BLENDED"
    return mat


def fill_mesh(mesh, node):
    """Writes the node's primitives into `mesh` (in the node's frame): its geometry, a
    ``UVMap`` layer (planar, metres, as the exports' UVs) and a material slot per primitive.
    A mesh Clay filled before keeps its slots when their number is unchanged, so a material
    the user put in a slot stays there."""
    import numpy as np

    verts, faces, slots, uvs = [], [], [], []
    base = 0
    for k, prim in enumerate(node.primitives):
        p = np.asarray(prim.positions, dtype=np.float64)
        verts.append(p)
        faces.append(np.asarray(prim.triangles, dtype=np.int64) + base)
        slots.append(np.full(len(prim.triangles), k, dtype=np.int32))
        uvs.append(np.asarray(prim.uvs, dtype=np.float64))
        base += len(p)
    mesh.clear_geometry()
    if len(mesh.materials) != len(node.primitives):
        mesh.materials.clear()
        for prim in node.primitives:
            mesh.materials.append(material_for(prim))
    if verts:
        v, f = np.concatenate(verts), np.concatenate(faces)
        mesh.from_pydata(v.tolist(), [], f.tolist())
        mesh.polygons.foreach_set("material_index", np.concatenate(slots))
        mesh.polygons.foreach_set("use_smooth", np.zeros(len(f), dtype=bool))
        uv = mesh.uv_layers.new(name="UVMap")
        corners = np.empty(len(mesh.loops), dtype=np.int64)
        mesh.loops.foreach_get("vertex_index", corners)
        uv.data.foreach_set("uv", np.concatenate(uvs)[corners].ravel())
        mesh.validate()
        mesh.update()
    mesh[MESH] = node.mesh or node.name
    return mesh


def set_node(obj, node, root):
    """Places a Clay object as the export's node under the root, with the glTF importer's
    properties (the export's extras: ``instance``, ``piece``, ``state``, ``id``, ``chain``,
    ``index``) and its node name, the identity it keeps across reloads."""
    import math

    x, y = node.pivot
    turn = node.rotation
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(turn)):
        x, y, turn = 0.0, 0.0, 0.0
    if obj.parent != root:
        obj.parent = root
        obj.matrix_parent_inverse.identity()
    obj.location = (x, y, 0.0)
    obj.rotation_euler = (0.0, 0.0, turn)
    obj[NODE] = node.name
    obj["instance"] = node.instance
    obj["piece"] = node.piece
    obj["state"] = node.state
    obj["id"] = node.id
    for key, value in (("chain", node.chain), ("index", node.index)):
        if value is None:
            obj.pop(key, None)
        else:
            obj[key] = value


def root_of(collection):
    """The collection's root Empty, made (named after the collection) when it has none."""
    for obj in collection.objects:
        if obj.get(ROOT):
            return obj
    root = bpy.data.objects.new(collection.name, None)
    root.empty_display_type = "PLAIN_AXES"
    root[ROOT] = True
    collection.objects.link(root)
    return root


def update_objects(collection, nodes):
    """Brings the collection's Clay objects to `nodes`, in place: an object whose node is still
    there keeps its object (the user's modifiers, object materials, children, properties),
    takes the node's placement and mesh; a new node gets an object under the root; a gone
    node's object is removed, its children kept under the root where they are. Objects Clay
    did not make are never touched."""
    root = root_of(collection)
    old = {o[NODE]: o for o in collection.objects if NODE in o}
    old_meshes = {}
    for obj in old.values():
        if obj.type == "MESH" and MESH in obj.data:
            old_meshes.setdefault(obj.data[MESH], obj.data)
    meshes = {}
    for node in nodes:
        key = node.mesh or node.name
        mesh = meshes.get(key)
        if mesh is None:
            mesh = old_meshes.pop(key, None) or bpy.data.meshes.new(key)
            meshes[key] = fill_mesh(mesh, node)
        obj = old.pop(node.name, None)
        if obj is None:
            obj = bpy.data.objects.new(node.name, mesh)
            collection.objects.link(obj)
        elif obj.data != mesh:
            obj.data = mesh
        set_node(obj, node, root)
    for obj in old.values():
        for child in list(obj.children):
            world = child.matrix_world.copy()
            child.parent = root
            child.matrix_world = world
        bpy.data.objects.remove(obj, do_unlink=True)
    for mesh in old_meshes.values():
        if mesh.users == 0:
            bpy.data.meshes.remove(mesh)


def stored_path(path, blend=None):
    """A path as the collection keeps it: relative to the .blend (``//grammars/wall.clay``)
    when the .blend has a place (`blend`, else the open file's) and the path is on its drive,
    else absolute. `path` may be relative to the open .blend itself."""
    if not path:
        return ""
    path = os.path.abspath(bpy.path.abspath(path))
    blend = blend or bpy.data.filepath
    if blend:
        try:
            return bpy.path.relpath(path, start=os.path.dirname(os.path.abspath(blend)))
        except ValueError:  # another drive (Windows)
            pass
    return path


@bpy.app.handlers.persistent  # kept across file loads, as the add-on is
def make_paths_relative(target=None, *_args):
    """Before a save (``save_pre``, given the file's new path): the paths of every Clay
    collection relative to where the .blend is written, so the .blend and its grammars move
    together and reopen from anywhere."""
    blend = target if isinstance(target, str) and target else None
    for coll in bpy.data.collections:
        for key in (PATH, SCRIPT):
            if coll.get(key):
                coll[key] = stored_path(coll[key], blend)


def collection_params(collection):
    """The parameter values set on a collection the add-on made, by name."""
    names = json.loads(collection.get(PARAMS, "[]"))
    return {n: float(collection[n]) for n in names if n in collection}


def build(collection, path, script, params, thickness):
    """Brings `collection` to the grammar's model (after the script, when one is given), in
    place (`update_objects`); sets the collection's properties. `path` and `script` may be
    relative to the .blend (``//``). Raises the package's errors (clay.GrammarError,
    ValueError, OSError) before anything in the collection changes."""
    clay = _clay()
    grammar_path = bpy.path.abspath(path)
    script_path = bpy.path.abspath(script) if script else ""
    if params:
        # Values for parameters the grammar no longer declares (its text changed) are dropped.
        known = {p.name for p in clay.Grammar.open(grammar_path).params}
        params = {k: v for k, v in params.items() if k in known}
    grammar = clay.Grammar.open(grammar_path, params=params or None)
    session = clay.Session(grammar)
    notes = []
    if script_path:
        try:
            session.run_script(script_path)
        except clay.ScriptParamsError as e:
            # Recorded with other parameter values: replayed here it would fold the model
            # (issue 48). The model is shown without it, and the user told why.
            session = clay.Session(grammar)
            notes.append(f"the script was not replayed: {e}")
    nodes = session.scene(thickness=thickness)
    update_objects(collection, nodes)
    collection[PATH] = stored_path(path)
    collection[SCRIPT] = stored_path(script)
    collection[THICKNESS] = float(thickness)
    for stale in json.loads(collection.get(PARAMS, "[]")):
        if stale in collection:
            del collection[stale]
    names = []
    for p in grammar.params:
        # A count (a whole default and whole range ends, as the editor's sliders step) is an
        # integer property; any other parameter a float (issue 48: `bays` showed 6.0).
        whole = float(p.default).is_integer() and all(
            float(x).is_integer() for x in (p.range or ())
        )
        kind = int if whole and float(p.value).is_integer() else float
        collection[p.name] = kind(p.value)
        ui = collection.id_properties_ui(p.name)
        options = {"default": kind(p.default), "description": f"Clay parameter {p.name}"}
        if p.range is not None:
            lo, hi = (kind(x) for x in p.range)
            options.update(min=lo, max=hi, soft_min=lo, soft_max=hi)
        ui.update(**options)
        names.append(p.name)
    collection[PARAMS] = json.dumps(names)
    return len(nodes), notes


def import_grammar(context, path, script="", thickness=DEFAULT_THICKNESS):
    """A new collection (named after the grammar's file) in the scene, built by `build`."""
    name = os.path.splitext(os.path.basename(path))[0] or "clay"
    collection = bpy.data.collections.new(name)
    try:
        count, notes = build(collection, path, script, {}, thickness)
    except BaseException:
        bpy.data.collections.remove(collection)
        raise
    context.scene.collection.children.link(collection)
    return collection, count, notes


def report_error(op, e):
    op.report({"ERROR"}, f"Clay: {e}")
    return {"CANCELLED"}


class CLAY_OT_import_grammar(bpy.types.Operator, ImportHelper):
    """Import a Clay grammar (.clay) as a collection: an object per instance"""

    bl_idname = "clay.import_grammar"
    bl_label = "Import Clay grammar"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".clay"
    filter_glob: StringProperty(default="*.clay", options={"HIDDEN"})
    script: StringProperty(
        name="Script",
        description="A sculpting script (JSON, docs/scripts.md) to run before importing; empty: the initial model",
        default="",
        subtype="FILE_PATH",
    )
    thickness: FloatProperty(
        name="Thickness",
        description="Height of flat proxy geometry, in metres (as clayc export --thickness)",
        default=DEFAULT_THICKNESS,
        min=1e-6,
        max=1000.0,
        unit="LENGTH",
    )

    def execute(self, context):
        try:
            collection, count, notes = import_grammar(
                context, self.filepath, bpy.path.abspath(self.script), self.thickness
            )
        except Exception as e:
            return report_error(self, e)
        for note in notes:
            self.report({"WARNING"}, f"Clay: {note}")
        self.report({"INFO"}, f"Clay: {count} instances into collection {collection.name}")
        return {"FINISHED"}


def clay_collection(context, name=""):
    """The collection to reload: the named one, else the active one, if the add-on made it."""
    coll = bpy.data.collections.get(name) if name else context.collection
    if coll is not None and PATH in coll:
        return coll
    return None


class CLAY_OT_reload(bpy.types.Operator):
    """Re-read the collection's Clay grammar (and script) with its parameter values"""

    bl_idname = "clay.reload"
    bl_label = "Reload Clay grammar"
    bl_options = {"REGISTER", "UNDO"}

    collection: StringProperty(
        name="Collection",
        description="The collection to reload (empty: the active collection)",
        default="",
    )

    @classmethod
    def poll(cls, context):
        return True

    def execute(self, context):
        coll = clay_collection(context, self.collection)
        if coll is None:
            self.report({"ERROR"}, "Clay: the collection was not imported from a Clay grammar")
            return {"CANCELLED"}
        try:
            count, notes = build(
                coll,
                coll[PATH],
                coll.get(SCRIPT, ""),
                collection_params(coll),
                float(coll.get(THICKNESS, DEFAULT_THICKNESS)),
            )
        except Exception as e:
            return report_error(self, e)
        for note in notes:
            self.report({"WARNING"}, f"Clay: {note}")
        self.report({"INFO"}, f"Clay: {count} instances reloaded into {coll.name}")
        return {"FINISHED"}


class CLAY_PT_collection(bpy.types.Panel):
    """The grammar, its parameters and Reload, in Properties > Collection"""

    bl_label = "Clay"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "collection"

    @classmethod
    def poll(cls, context):
        return clay_collection(context) is not None

    def draw(self, context):
        coll = clay_collection(context)
        layout = self.layout
        layout.label(text=os.path.basename(coll[PATH]), icon="FILE_TEXT")
        if coll.get(SCRIPT):
            layout.label(text=os.path.basename(coll[SCRIPT]), icon="FILE_SCRIPT")
        for name in json.loads(coll.get(PARAMS, "[]")):
            if name in coll:
                layout.prop(coll, f'["{name}"]', text=name)
        op = layout.operator(CLAY_OT_reload.bl_idname, text="Reload", icon="FILE_REFRESH")
        op.collection = coll.name


def menu_import(self, context):
    self.layout.operator(CLAY_OT_import_grammar.bl_idname, text="Clay grammar (.clay)")


CLASSES = (CLAY_OT_import_grammar, CLAY_OT_reload, CLAY_PT_collection)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)
    bpy.app.handlers.save_pre.append(make_paths_relative)


def unregister():
    if make_paths_relative in bpy.app.handlers.save_pre:
        bpy.app.handlers.save_pre.remove(make_paths_relative)
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)

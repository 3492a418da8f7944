"""Clay grammars in Blender: File > Import > Clay grammar (.clay).

A grammar (and, optionally, a sculpting script) is imported as one collection: an object per
instance at its own pivot (the instance's centroid) and turned as its rest state is, named as
in ``clayc export``'s glTF (``wall_n_4``, the fifth brick of chain ``wall_n``; custom
properties ``clay_instance``, ``clay_piece``, ``clay_state``, ``clay_chain``, ``clay_index``),
identical instances sharing one mesh, one material per fill colour, heights as ``clayc export`` gives them (metres,
z up). The grammar's parameters become properties of the collection (Properties > Collection
> Clay); Reload re-reads the grammar, with those values, and its script.

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


def material_for(colour):
    """The material of a fill colour (sRGB bytes r, g, b, a), made once per file."""
    r, g, b, a = colour
    name = f"clay #{r:02x}{g:02x}{b:02x}{a:02x}"
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


def mesh_data(node):
    """The node's primitives as one Blender mesh in the node's frame, a material each."""
    import numpy as np

    verts, faces, slots = [], [], []
    base = 0
    for k, prim in enumerate(node.primitives):
        p = np.asarray(prim.positions, dtype=np.float64)
        t = np.asarray(prim.triangles, dtype=np.int64) + base
        verts.append(p)
        faces.append(t)
        slots.append(np.full(len(t), k, dtype=np.int32))
        base += len(p)
    mesh = bpy.data.meshes.new(node.mesh or node.name)
    if verts:
        v = np.concatenate(verts)
        f = np.concatenate(faces)
        mesh.from_pydata(v.tolist(), [], f.tolist())
        for prim in node.primitives:
            mesh.materials.append(material_for(prim.colour))
        mesh.polygons.foreach_set("material_index", np.concatenate(slots))
        mesh.polygons.foreach_set("use_smooth", np.zeros(len(f), dtype=bool))
        mesh.validate()
        mesh.update()
    return mesh


def mesh_object(node, collection, meshes):
    """One instance as an object at its pivot, turned as the export's node, with the node's
    shared mesh (`meshes`: the meshes made so far, by name)."""
    import math

    mesh = meshes.get(node.mesh) if node.mesh is not None else None
    if mesh is None:
        mesh = mesh_data(node)
        if node.mesh is not None:
            meshes[node.mesh] = mesh
    obj = bpy.data.objects.new(node.name, mesh)
    x, y = node.pivot
    turn = node.rotation
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(turn)):
        x, y, turn = 0.0, 0.0, 0.0
    obj.location = (x, y, 0.0)
    obj.rotation_euler = (0.0, 0.0, turn)
    obj["clay_instance"] = node.instance
    obj["clay_piece"] = node.piece
    obj["clay_state"] = node.state
    obj["clay_id"] = node.id
    if node.chain is not None:
        obj["clay_chain"] = node.chain
        obj["clay_index"] = node.index
    collection.objects.link(obj)
    return obj


def collection_params(collection):
    """The parameter values set on a collection the add-on made, by name."""
    names = json.loads(collection.get(PARAMS, "[]"))
    return {n: float(collection[n]) for n in names if n in collection}


def build(collection, path, script, params, thickness):
    """Fills `collection` with the grammar's model (after the script, when one is given);
    sets the collection's properties. Raises the package's errors (clay.GrammarError,
    ValueError, OSError) before anything in the collection changes."""
    clay = _clay()
    if params:
        # Values for parameters the grammar no longer declares (its text changed) are dropped.
        known = {p.name for p in clay.Grammar.open(path).params}
        params = {k: v for k, v in params.items() if k in known}
    grammar = clay.Grammar.open(path, params=params or None)
    session = clay.Session(grammar)
    if script:
        session.run_script(script)
    nodes = session.scene(thickness=thickness)
    for obj in list(collection.objects):
        mesh = obj.data if obj.type == "MESH" else None
        bpy.data.objects.remove(obj, do_unlink=True)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)
    meshes = {}
    for node in nodes:
        mesh_object(node, collection, meshes)
    collection[PATH] = str(path)
    collection[SCRIPT] = str(script or "")
    collection[THICKNESS] = float(thickness)
    for stale in json.loads(collection.get(PARAMS, "[]")):
        if stale in collection:
            del collection[stale]
    names = []
    for p in grammar.params:
        collection[p.name] = float(p.value)
        ui = collection.id_properties_ui(p.name)
        options = {"default": float(p.default), "description": f"Clay parameter {p.name}"}
        if p.range is not None:
            lo, hi = p.range
            options.update(min=float(lo), max=float(hi), soft_min=float(lo), soft_max=float(hi))
        ui.update(**options)
        names.append(p.name)
    collection[PARAMS] = json.dumps(names)
    return len(nodes)


def import_grammar(context, path, script="", thickness=DEFAULT_THICKNESS):
    """A new collection (named after the grammar's file) in the scene, built by `build`."""
    name = os.path.splitext(os.path.basename(path))[0] or "clay"
    collection = bpy.data.collections.new(name)
    try:
        count = build(collection, path, script, {}, thickness)
    except BaseException:
        bpy.data.collections.remove(collection)
        raise
    context.scene.collection.children.link(collection)
    return collection, count


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
            collection, count = import_grammar(
                context, self.filepath, bpy.path.abspath(self.script), self.thickness
            )
        except Exception as e:
            return report_error(self, e)
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
            count = build(
                coll,
                coll[PATH],
                coll.get(SCRIPT, ""),
                collection_params(coll),
                float(coll.get(THICKNESS, DEFAULT_THICKNESS)),
            )
        except Exception as e:
            return report_error(self, e)
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


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)

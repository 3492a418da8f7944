"""Clay grammars in Blender: File > Import > Clay grammar (.clay).

A grammar (and, optionally, a sculpting script) is imported as one collection: a root Empty
named after the grammar and under it an object per instance at its own pivot (the instance's
centroid), turned as its rest state is, named as in ``clayc export``'s glTF (``wall_n_4``, the
fifth brick of chain ``wall_n``) with the properties Blender's glTF importer gives from its
extras (``instance``, ``piece``, ``state``, ``id``, ``chain``, ``index``); identical instances
share one mesh with a planar ``UVMap``, one material per fill colour named as in every export
(``fill_9a958cff``), heights as ``clayc export`` gives them (metres, z up). The grammar's
parameters become typed properties of the collection (Properties > Collection > Clay): a
whole number an integer, a ``bool`` a checkbox, a ``choice`` a menu of its pieces; changing one
rebuilds the model (a ``depsgraph_update_post`` handler), as Reload does.

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
from bpy.app.handlers import persistent
from bpy.props import EnumProperty, FloatProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

# Custom properties the add-on keeps on a collection it made.
PATH = "clay_path"
SCRIPT = "clay_script"
THICKNESS = "clay_thickness"
PARAMS = "clay_params"
# The parameter values the collection was last built with (JSON), a choice's pieces by name
# (JSON), and the error of the last rebuild a parameter change asked for.
BUILT = "clay_built"
CHOICES = "clay_choices"
ERROR = "clay_error"
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
    """The parameter values set on a collection the add-on made, by name, as their properties
    hold them: a bool, an int, a float or a str (a choice)."""
    names = json.loads(collection.get(PARAMS, "[]"))
    out = {}
    for n in names:
        if n in collection:
            v = collection[n]
            out[n] = v if isinstance(v, (bool, int, float, str)) else float(v)
    return out


def set_param_property(collection, p):
    """The collection's property for grammar parameter `p`, of its type: a checkbox for a
    ``bool``, a text naming a piece for a ``choice`` (the panel offers its pieces in a menu), an
    integer for an ``int`` or ``seed`` (and for a number whose default and range are whole, as
    the editor's sliders step), a float otherwise."""
    description = f"Clay parameter {p.name} ({p.kind})"
    if p.kind == "bool":
        collection[p.name] = bool(p.value)
        collection.id_properties_ui(p.name).update(default=bool(p.default), description=description)
        return
    if p.kind == "choice":
        collection[p.name] = str(p.value)
        collection.id_properties_ui(p.name).update(description=description)
        return
    whole = p.kind in ("int", "seed") or (
        float(p.default).is_integer()
        and all(float(x).is_integer() for x in (p.range or ()))
        and float(p.value).is_integer()
    )
    kind = int if whole else float
    collection[p.name] = kind(p.value)
    options = {"default": kind(p.default), "description": description}
    if p.range is not None:
        lo, hi = (kind(x) for x in p.range)
        options.update(min=lo, max=hi, soft_min=lo, soft_max=hi)
    elif p.kind == "seed":
        options.update(min=0, soft_min=0)
    collection.id_properties_ui(p.name).update(**options)


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
    for p in grammar.params:
        set_param_property(collection, p)
    collection[PARAMS] = json.dumps([p.name for p in grammar.params])
    collection[CHOICES] = json.dumps({p.name: p.choices for p in grammar.params if p.choices})
    collection[BUILT] = json.dumps(collection_params(collection))
    if ERROR in collection:
        del collection[ERROR]
    return len(nodes), notes


def rebuild(collection):
    """Builds `collection` again from its stored grammar, script and parameter values."""
    return build(
        collection,
        collection[PATH],
        collection.get(SCRIPT, ""),
        collection_params(collection),
        float(collection.get(THICKNESS, DEFAULT_THICKNESS)),
    )


_rebuilding = False


@persistent
def rebuild_changed(scene=None, depsgraph=None):
    """After any change (``depsgraph_update_post``): every Clay collection whose parameter
    properties differ from the values it was built with is rebuilt, as Reload would; an error
    is kept on the collection (the panel shows it) and the model stays as it was."""
    global _rebuilding
    if _rebuilding:
        return
    for coll in list(bpy.data.collections):
        if PATH not in coll:
            continue
        values = collection_params(coll)
        if json.dumps(values) == coll.get(BUILT, json.dumps(values)):
            continue
        _rebuilding = True
        try:
            rebuild(coll)
        except Exception as e:
            # Not tried again until a value changes once more.
            coll[BUILT] = json.dumps(values)
            coll[ERROR] = str(e)
        finally:
            _rebuilding = False


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
            count, notes = rebuild(coll)
        except Exception as e:
            return report_error(self, e)
        for note in notes:
            self.report({"WARNING"}, f"Clay: {note}")
        self.report({"INFO"}, f"Clay: {count} instances reloaded into {coll.name}")
        return {"FINISHED"}


# Blender keeps no reference to an enum's strings made by a callback: they are kept here.
_choice_items_cache = []


def _choice_items(self, context):
    coll = bpy.data.collections.get(self.collection)
    choices = json.loads(coll.get(CHOICES, "{}")).get(self.param, []) if coll else []
    _choice_items_cache[:] = [(c, c, f"The piece {c}") for c in choices]
    return _choice_items_cache


class CLAY_OT_set_choice(bpy.types.Operator):
    """Pick the piece of a Clay choice parameter and rebuild the model"""

    bl_idname = "clay.set_choice"
    bl_label = "Choose a piece"
    bl_options = {"REGISTER", "UNDO"}

    collection: StringProperty(name="Collection", default="")
    param: StringProperty(name="Parameter", default="")
    value: EnumProperty(name="Piece", items=_choice_items)

    def execute(self, context):
        coll = clay_collection(context, self.collection)
        if coll is None or self.param not in coll:
            self.report({"ERROR"}, "Clay: no such Clay collection or parameter")
            return {"CANCELLED"}
        before = coll[self.param]
        coll[self.param] = self.value
        try:
            count, notes = rebuild(coll)
        except Exception as e:
            coll[self.param] = before
            return report_error(self, e)
        for note in notes:
            self.report({"WARNING"}, f"Clay: {note}")
        self.report({"INFO"}, f"Clay: {self.param} = {self.value}, {count} instances")
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
        choices = json.loads(coll.get(CHOICES, "{}"))
        for name in json.loads(coll.get(PARAMS, "[]")):
            if name not in coll:
                continue
            if name in choices:
                row = layout.row()
                row.label(text=name)
                op = row.operator_menu_enum(CLAY_OT_set_choice.bl_idname, "value", text=str(coll[name]))
                op.collection, op.param = coll.name, name
            else:
                layout.prop(coll, f'["{name}"]', text=name)
        if coll.get(ERROR):
            layout.label(text=coll[ERROR].splitlines()[0], icon="ERROR")
        op = layout.operator(CLAY_OT_reload.bl_idname, text="Reload", icon="FILE_REFRESH")
        op.collection = coll.name


def menu_import(self, context):
    self.layout.operator(CLAY_OT_import_grammar.bl_idname, text="Clay grammar (.clay)")


CLASSES = (CLAY_OT_import_grammar, CLAY_OT_reload, CLAY_OT_set_choice, CLAY_PT_collection)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)
    bpy.app.handlers.save_pre.append(make_paths_relative)
    bpy.app.handlers.depsgraph_update_post.append(rebuild_changed)


def unregister():
    if rebuild_changed in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(rebuild_changed)
    if make_paths_relative in bpy.app.handlers.save_pre:
        bpy.app.handlers.save_pre.remove(make_paths_relative)
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)

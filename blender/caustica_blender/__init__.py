"""caustica as a Blender render engine: press F12, get caustics.

The add-on turns the evaluated scene (modifiers applied) into a `caustica.Scene` through
`caustica.Scene.from_dict` and renders it pass by pass, the image in Blender's editor after each
pass. It needs the `caustica` Python package importable from Blender's Python (docs/blender.md).
"""

bl_info = {
    "name": "caustica",
    "author": "the caustica developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine > caustica",
    "description": "Caustics by photon mapping and vertex connection and merging",
    "category": "Render",
}

if "bpy" in locals():
    import importlib

    importlib.reload(settings)  # noqa: F821 (a reload inside Blender)
    importlib.reload(convert)  # noqa: F821
    importlib.reload(engine)  # noqa: F821
else:
    from . import convert, engine, settings

import bpy


def register():
    settings.register()
    bpy.utils.register_class(engine.CausticaRenderEngine)
    for panel in engine.compatible_panels():
        panel.COMPAT_ENGINES.add(engine.CausticaRenderEngine.bl_idname)


def unregister():
    for panel in engine.compatible_panels():
        panel.COMPAT_ENGINES.discard(engine.CausticaRenderEngine.bl_idname)
    bpy.utils.unregister_class(engine.CausticaRenderEngine)
    settings.unregister()

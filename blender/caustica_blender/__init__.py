"""caustica as a Blender render engine: press F12, get caustics.

The add-on turns the evaluated scene (modifiers applied) into a `caustica.Scene` through
`caustica.Scene.from_dict` and renders it pass by pass, the image in Blender's editor after each
pass. It needs the `caustica` Python package importable from Blender's Python (docs/blender.md).
Its unit rules (`rules.py`) import nothing of Blender's, so they are tested outside it.
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


def register():
    import bpy

    from . import engine, settings

    settings.register()
    bpy.utils.register_class(engine.CausticaRenderEngine)
    for panel in engine.compatible_panels():
        panel.COMPAT_ENGINES.add(engine.CausticaRenderEngine.bl_idname)


def unregister():
    import bpy

    from . import engine, settings

    for panel in engine.compatible_panels():
        panel.COMPAT_ENGINES.discard(engine.CausticaRenderEngine.bl_idname)
    bpy.utils.unregister_class(engine.CausticaRenderEngine)
    settings.unregister()

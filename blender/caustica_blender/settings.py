"""The add-on's render settings, `scene.caustica`, and their panel in Render Properties."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty


class CausticaSettings(bpy.types.PropertyGroup):
    integrator: EnumProperty(
        name="Integrator",
        items=[
            ("VCM", "VCM", "Vertex connection and merging: caustics and everything else (the default)"),
            ("PPM", "PPM", "Progressive photon mapping"),
            ("PATH", "Path", "Path tracing with next-event estimation: no caustics of point lights"),
            ("LT", "Light tracing", "Paths from the lights to the camera"),
            ("GI", "GI", "Photon-mapped global illumination with final gathering"),
        ],
        default="VCM",
    )
    time_limit: FloatProperty(
        name="Time limit", description="Seconds to render for; 0 renders the passes", default=10.0, min=0.0, unit="TIME_ABSOLUTE"
    )
    passes: IntProperty(name="Passes", description="Passes when there is no time limit", default=64, min=1)
    seed: IntProperty(name="Seed", default=0, min=0)
    photons: IntProperty(
        name="Photons per pass", description="0: the integrator's own choice", default=0, min=0
    )
    radius: FloatProperty(
        name="Radius", description="Photon gather radius in scene units; 0: the integrator's own choice", default=0.0, min=0.0
    )
    area_lights: EnumProperty(
        name="Area lights",
        items=[
            (
                "AUTO",
                "Automatic",
                "Glowing surfaces, seen in mirrors and glass as Cycles' lamps are; a lamp in the camera's view is a light, unseen by it",
            ),
            ("LIGHT", "Lights", "Lights alone: unseen by the camera, as Cycles' are, and unseen in mirrors and glass"),
            (
                "SURFACE",
                "Glowing surfaces",
                "Surfaces of the same radiance: seen in mirrors and glass (and by the camera), their backs black",
            ),
        ],
        default="AUTO",
    )
    spectral: BoolProperty(
        name="Spectral", description="Transport by wavelength (dispersion in glass with an Abbe number)", default=False
    )


class CAUSTICA_PT_settings(bpy.types.Panel):
    bl_label = "caustica"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {"CAUSTICA"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        s = context.scene.caustica
        layout = self.layout
        layout.use_property_split = True
        layout.prop(s, "integrator")
        layout.prop(s, "time_limit")
        row = layout.row()
        row.enabled = s.time_limit == 0.0
        row.prop(s, "passes")
        layout.prop(s, "seed")
        if s.integrator in {"VCM", "PPM", "GI", "LT"}:
            layout.prop(s, "photons")
        if s.integrator in {"VCM", "PPM", "GI"}:
            layout.prop(s, "radius")
        layout.prop(s, "area_lights")
        layout.prop(s, "spectral")


def register():
    bpy.utils.register_class(CausticaSettings)
    bpy.utils.register_class(CAUSTICA_PT_settings)
    bpy.types.Scene.caustica = PointerProperty(type=CausticaSettings)


def unregister():
    del bpy.types.Scene.caustica
    bpy.utils.unregister_class(CAUSTICA_PT_settings)
    bpy.utils.unregister_class(CausticaSettings)

"""The render engine: F12 converts the evaluated scene and renders it pass by pass, the image in
Blender's editor after each pass, progress in the status bar; Esc stops and keeps what is done.
The Combined pass is linear, so Blender's colour management applies as to Cycles' images."""

import time

import bpy
import numpy as np

from . import rules
from .convert import Conversion


def compatible_panels():
    """Blender's own panels that apply to caustica as they do to Cycles (output size, colour
    management, the camera and light data)."""
    names = [
        "RENDER_PT_format",
        "RENDER_PT_frame_range",
        "RENDER_PT_color_management",
        "RENDER_PT_color_management_curves",
        "DATA_PT_lens",
        "DATA_PT_camera",
        "DATA_PT_light",
        "DATA_PT_EEVEE_light",
        "DATA_PT_spot",
        "DATA_PT_context_light",
        "MATERIAL_PT_preview",
        "EEVEE_MATERIAL_PT_context_material",
        "EEVEE_MATERIAL_PT_surface",
        "WORLD_PT_context_world",
        "EEVEE_WORLD_PT_surface",
    ]
    return [getattr(bpy.types, n) for n in names if hasattr(bpy.types, n)]


def render_options(settings):
    options = {
        "integrator": settings.integrator.lower(),
        "seed": settings.seed,
        "spectral": True if settings.spectral else None,
    }
    if settings.time_limit > 0.0:
        options["time"] = settings.time_limit
    else:
        options["passes"] = settings.passes
    if settings.photons > 0 and settings.integrator in {"PPM", "GI"}:
        options["photons"] = settings.photons
    if settings.radius > 0.0 and settings.integrator in {"VCM", "PPM", "GI"}:
        options["radius"] = settings.radius
    return options


class CausticaRenderEngine(bpy.types.RenderEngine):
    bl_idname = "CAUSTICA"
    bl_label = "caustica"
    bl_use_preview = False

    def render(self, depsgraph):
        import caustica

        scene = depsgraph.scene
        scale = scene.render.resolution_percentage / 100.0
        width = int(scene.render.resolution_x * scale)
        height = int(scene.render.resolution_y * scale)
        # With a render border, Blender's result is the border's pixels alone: only they are
        # rendered, through the same camera.
        result = self.begin_result(0, 0, width, height)
        crop = None
        if scene.render.use_border:
            r = scene.render
            crop = rules.border(r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y, width, height)
            # The result's size is Blender's own rounding of the border.
            crop[1] = crop[0] + result.resolution_x
            crop[2] = crop[3] - result.resolution_y
        conversion = Conversion(depsgraph, width, height, crop)
        try:
            description = conversion.run()
            built = caustica.Scene.from_dict(description)
        except (ValueError, TypeError) as e:
            self.report({"ERROR"}, f"caustica: {e}")
            self.end_result(result)
            return
        for message in conversion.warnings + list(built.warnings):
            self.report({"WARNING"}, f"caustica: {message}")
        options = render_options(scene.caustica)
        if crop is not None:
            width, height = crop[1] - crop[0], crop[3] - crop[2]
        options.update(width=width, height=height)
        # Blender's Performance › Threads, as Cycles takes it.
        if scene.render.threads_mode == "FIXED":
            options["threads"] = scene.render.threads
        combined = result.layers[0].passes["Combined"]
        start = time.monotonic()
        planned = options.get("passes")
        with caustica.progressive(built, **options) as run:
            for done, image in enumerate(run, start=1):
                # Blender's rows run from the bottom; the alpha is 1 (no transparent film).
                rgba = np.ones((height, width, 4), dtype=np.float32)
                rgba[..., :3] = image[::-1]
                combined.rect = rgba.reshape(-1, 4)
                self.update_result(result)
                elapsed = time.monotonic() - start
                if planned:
                    fraction = done / planned
                else:
                    fraction = min(1.0, elapsed / max(options["time"], 1e-6))
                self.update_progress(fraction)
                left = elapsed * (1.0 - fraction) / max(fraction, 1e-6)
                self.update_stats("", f"caustica: pass {done}, {elapsed:.1f} s, about {left:.0f} s left")
                if self.test_break():
                    run.cancel()
                    break
        self.end_result(result)

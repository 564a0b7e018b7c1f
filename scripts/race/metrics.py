#!/usr/bin/env python3
"""Errors of a render of the shared reference's Cornell box against the reference EXR.

usage: metrics.py IMAGE.exr REFERENCE.exr [--scene point|area] [--json]
       metrics.py --mask-png OUT.png [--scene point|area] [IMAGE.exr]   (draws the masks)

All on linear RGB at 160x160, rows from the top, columns from the left. See README.md:
  focus    largest relative error over R, G, B of the mean of the 5x5 box rows 135-139,
           cols 41-45, less its specular pixels (17 are left); also signed, from the RGB sum
  caustic  relMSE over rows 134-142, cols 36-60, less the specular mask (141 px)
  image    relMSE over the whole image less the specular mask dilated by one pixel
relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 1e-2).
The specular mask comes from the geometry: a pixel is specular when any of 16x16 rays through
it from the reference camera meets the glass or mirror sphere, or (area scene) the light sphere.
"""
import argparse, functools, json, sys
import numpy as np

W = H = 160
FOV_X = 40.0                                   # the reference camera: perspective, fov on x,
ORIGIN = np.array([0.0, 1.0, 3.6])             # from (0, 1, 3.6) looking down -z
SPHERES = {'glass': ((-0.45, 0.35, -0.2), 0.35),
           'mirror': ((0.45, 0.35, 0.3), 0.35),
           'light': ((0.0, 1.8, 0.0), 0.08)}   # area scene only
FOCUS = (slice(135, 140), slice(41, 46))
CAUSTIC = (slice(134, 143), slice(36, 61))
EPS = 1e-2


@functools.lru_cache(maxsize=None)
def specular_mask(scene, sub=16):
    """True where a pixel's footprint (the pixel itself: box filter) meets a specular sphere."""
    t = np.tan(np.radians(FOV_X) / 2)
    o = (np.arange(sub) + 0.5) / sub
    cols = (np.arange(W)[:, None] + o).ravel()
    rows = (np.arange(H)[:, None] + o).ravel()
    X, Y = np.meshgrid((2 * cols / W - 1) * t, -(2 * rows / H - 1) * t * H / W)   # rows go down
    d = np.stack([X, Y, -np.ones_like(X)], axis=-1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    hit = np.zeros(X.shape, dtype=bool)
    for name, (c, r) in SPHERES.items():
        if name == 'light' and scene != 'area':
            continue
        oc = ORIGIN - np.array(c)
        b = d @ oc
        disc = b * b - (oc @ oc - r * r)
        hit |= (disc >= 0) & (-b + np.sqrt(np.maximum(disc, 0)) > 0)
    m = hit.reshape(H, sub, W, sub).any(axis=(1, 3))
    m.flags.writeable = False   # cached: shared by every caller
    return m


def dilate(m):
    """m grown by one pixel in all 8 directions."""
    p = np.pad(m, 1)
    return np.any([p[1 + dy:1 + dy + H, 1 + dx:1 + dx + W] for dy in (-1, 0, 1) for dx in (-1, 0, 1)], axis=0)


def read_exr(path):
    """An EXR as a float64 (H, W, 3) array (read with Mitsuba's Bitmap)."""
    import mitsuba as mi
    if mi.variant() is None:
        mi.set_variant('scalar_rgb')
    a = np.array(mi.Bitmap(path), dtype=np.float64)
    if a.ndim == 2:
        a = a[:, :, None].repeat(3, axis=2)
    return a[:, :, :3]


def rel_mse(x, ref, keep, eps=EPS):
    return float(((x - ref) ** 2 / (ref ** 2 + eps))[keep].mean())


def measures(img, ref, scene, eps=EPS):
    if img.shape != ref.shape:
        sys.exit(f'image {img.shape} and reference {ref.shape} differ in size')
    keep = ~specular_mask(scene)
    # (a) focus: the box mean over its non-specular pixels
    fk = keep[FOCUS]
    xm, rm = img[FOCUS][fk].mean(axis=0), ref[FOCUS][fk].mean(axis=0)
    # (b) caustic region, (c) whole image less the dilated mask
    region = np.zeros_like(keep)
    region[CAUSTIC] = True
    image_keep = ~dilate(~keep)
    # the README's plain 25-pixel box: meaningful only for particle-view images, where the
    # glass is black as in the reference (Mitsuba ptracer, caustica --no-camera-specular)
    fx, fr = img[FOCUS].reshape(-1, 3).mean(axis=0), ref[FOCUS].reshape(-1, 3).mean(axis=0)
    return {'focus_rel_err': float(np.max(np.abs(xm - rm) / rm)),
            'focus_signed': float(xm.sum() / rm.sum() - 1),
            'caustic_relmse': rel_mse(img, ref, region & keep, eps),
            'image_relmse': rel_mse(img, ref, image_keep, eps),
            'focus_box25_signed': float(fx.sum() / fr.sum() - 1),
            'focus_pixels': int(fk.sum()), 'caustic_pixels': int((region & keep).sum()),
            'image_pixels': int(image_keep.sum()), 'finite': bool(np.isfinite(img).all())}


def guess_scene(*paths):
    for p in paths:
        for s in ('area', 'point'):
            if s in p:
                return s
    sys.exit('cannot tell the scene from the file names: give --scene point|area')


def write_mask_png(path, scene, image=None):
    """White: specular, grey: the dilation, red: focus box, blue: caustic region (over the image)."""
    import mitsuba as mi
    spec = specular_mask(scene)
    rgb = np.zeros((H, W, 3))
    if image:
        x = read_exr(image)
        rgb = x / (1 + x)
    box = np.zeros_like(spec)
    box[CAUSTIC] = True
    rgb[box & ~spec, 2] = 1.0
    box[:] = False
    box[FOCUS] = True
    rgb[box & ~spec] = [1, 0, 0]
    rgb[dilate(spec)] = 0.5
    rgb[spec] = 1.0
    if mi.variant() is None:
        mi.set_variant('scalar_rgb')
    mi.Bitmap((np.clip(rgb, 0, 1) ** (1 / 2.2)).astype(np.float32)).convert(
        mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, True).write(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('image', nargs='?')
    ap.add_argument('reference', nargs='?')
    ap.add_argument('--scene', choices=['point', 'area'])
    ap.add_argument('--json', action='store_true')
    ap.add_argument('--mask-png', help='write the masks to this PNG and exit')
    a = ap.parse_args()
    if a.mask_png:
        write_mask_png(a.mask_png, a.scene or 'area', a.image)
        return
    if not (a.image and a.reference):
        ap.error('IMAGE and REFERENCE are required')
    scene = a.scene or guess_scene(a.reference, a.image)
    m = measures(read_exr(a.image), read_exr(a.reference), scene)
    if a.json:
        print(json.dumps(m))
        return
    print(f"focus rel. error (max over RGB)  {m['focus_rel_err']:.4f}  "
          f"(signed {m['focus_signed']:+.4f}; {m['focus_pixels']} px)")
    print(f"caustic region relMSE            {m['caustic_relmse']:.5f} ({m['caustic_pixels']} px)")
    print(f"image relMSE (specular excluded) {m['image_relmse']:.5f} ({m['image_pixels']} px)")
    print(f"README's plain 5x5 box, signed   {m['focus_box25_signed']:+.4f} (particle-view images only)")


if __name__ == '__main__':
    main()

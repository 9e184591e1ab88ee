"""Image textures on lobe colours: an analytic render (a textured Lambertian plane under a
uniform white sky shows the filtered texture itself), orientation, wrap modes, files
(sRGB decoding), material files, and bad input."""
import json
import struct
import zlib

import numpy as np
import pytest

import kauri


def textured_plane(albedo, uv_scale=1.0, extent=1.0):
    """A plane in front of an orthographic camera; `albedo` is a texture / colour, or a material."""
    s = kauri.Scene(color_space="srgb")
    P = np.array([(-extent, -extent, 0), (extent, -extent, 0), (extent, extent, 0), (-extent, extent, 0)], np.float32)
    uv = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], np.float32) * uv_scale
    s.add_mesh(P, [[0, 1, 2, 3]], uvs=uv, material=albedo if isinstance(albedo, kauri.Material) else kauri.Lambert(albedo=albedo), name="plane")
    s.add_environment(color=(1, 1, 1))
    s.set_camera(kind="orthographic", eye=(0, 0, 5), target=(0, 0, 0), up=(0, 1, 0), width=2.0 * extent)
    return s


def gradient(h=8, w=8):
    """Linear in u and v: bilinear reconstruction and a symmetric pixel filter reproduce it
    exactly at pixel centres away from the edges."""
    u = (np.arange(w) + 0.5) / w
    v = 1 - (np.arange(h) + 0.5) / h  # row 0 is the top of the image: v near 1
    U, V = np.meshgrid(u, v)
    return np.stack([0.1 + 0.8 * U, 0.1 + 0.8 * V, 0.5 + 0.0 * U], -1).astype(np.float32)


def test_textured_plane_under_white_sky_shows_the_texture():
    # Radiance of a Lambertian plane under a unit sky is its albedo (no other surface), so
    # each pixel is the texture at that point: r grows left to right, g bottom to top.
    tex = gradient()
    out = kauri.render(textured_plane(kauri.ImageTexture(tex, wrap="clamp")), spp=1024, resolution=(16, 16),
                       max_depth=1, seed=3)
    img = out.rgba[:, :, :3]
    ys, xs = np.mgrid[0:16, 0:16]
    u, v = (xs + 0.5) / 16, 1 - (ys + 0.5) / 16
    inner = (slice(4, 12), slice(4, 12))  # keep the clamp zone and the sky at the border out
    np.testing.assert_allclose(img[..., 0][inner], (0.1 + 0.8 * u)[inner], rtol=0.02, atol=0.005)
    np.testing.assert_allclose(img[..., 1][inner], (0.1 + 0.8 * v)[inner], rtol=0.02, atol=0.005)
    np.testing.assert_allclose(img[..., 2][inner], 0.5, rtol=0.02)


def test_repeat_tiles_the_texture_and_clamp_does_not():
    tex = np.zeros((2, 2, 3), np.float32)
    tex[:, 0] = 0.9  # left column bright, right column dark
    tex[:, 1] = 0.1
    rep = kauri.render(textured_plane(kauri.ImageTexture(tex, wrap="repeat"), uv_scale=2.0), spp=64,
                       resolution=(32, 32), max_depth=1, filter="box").rgba[..., 0]
    cla = kauri.render(textured_plane(kauri.ImageTexture(tex, wrap="clamp"), uv_scale=2.0), spp=64,
                       resolution=(32, 32), max_depth=1, filter="box").rgba[..., 0]
    # Repeat: u = 2 gives two periods, so columns 8 (u = 0.53) and 24 (u = 1.53) match.
    np.testing.assert_allclose(rep[:, 8].mean(), rep[:, 24].mean(), rtol=0.03)
    # Clamp: beyond u = 1 the right column's value holds.
    np.testing.assert_allclose(cla[4:28, 20:28].mean(), 0.1, rtol=0.05)
    assert rep[4:28, 20:28].mean() > 0.3


def write_png(path, rgb8):
    h, w, _ = rgb8.shape
    raw = b"".join(b"\x00" + rgb8[i].tobytes() for i in range(h))

    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def test_png_texture_is_decoded_from_srgb(tmp_path):
    path = tmp_path / "grey.png"
    write_png(str(path), np.full((2, 3, 3), 128, np.uint8))
    t = kauri.ImageTexture(str(path))
    assert t.image.shape == (2, 3, 3)
    expected = ((128 / 255 + 0.055) / 1.055) ** 2.4  # IEC 61966-2-1
    np.testing.assert_allclose(t.image, expected, rtol=1e-5)


def test_material_file_texture_path_is_relative_to_the_file(tmp_path):
    write_png(str(tmp_path / "wood.png"), np.full((4, 4, 3), 200, np.uint8))
    spec = {"name": "floor", "lobes": [{"name": "base", "type": "lambert", "albedo": {"texture": "wood.png"}}]}
    (tmp_path / "m.json").write_text(json.dumps(spec))
    (m,) = kauri.Material.load(str(tmp_path / "m.json"))
    out = kauri.render(textured_plane(m), spp=64, resolution=(8, 8), max_depth=1)
    np.testing.assert_allclose(out.rgba[2:6, 2:6, :3].mean(), ((200 / 255 + 0.055) / 1.055) ** 2.4, rtol=0.02)


def test_bad_textures_raise_clear_errors(tmp_path):
    with pytest.raises(kauri.SceneError, match=r"texture 'hot'.*\[0, 1\]"):
        kauri.Lambert(albedo=kauri.ImageTexture(np.full((2, 2, 3), 1.5, np.float32), name="hot"))
    with pytest.raises(kauri.SceneError, match=r"texture 't': parameter 'image': expected an \(height, width, 3\)"):
        kauri.ImageTexture(np.zeros((4, 4)), name="t")
    with pytest.raises(kauri.SceneError, match="finite"):
        kauri.ImageTexture(np.full((2, 2, 3), np.nan, np.float32), name="t")
    with pytest.raises(kauri.SceneError, match="wrap"):
        kauri.ImageTexture(np.zeros((2, 2, 3)), wrap="mirror", name="t")
    missing = str(tmp_path / "nope.png")
    with pytest.raises(kauri.SceneError, match="nope.png"):
        kauri.ImageTexture(missing)
    with pytest.raises(kauri.SceneError, match="unknown parameter"):
        kauri.Material.from_dict({"name": "m", "lobes": [{"name": "b", "type": "lambert",
                                                          "albedo": {"texture": missing, "filter": "x"}}]})


def test_textured_sphere_reads_its_uv():
    # A convex Lambertian sphere under a unit sky shows its albedo. Sphere uv: u = φ/2π with
    # φ = atan2(n_y, n_x); the texture is red for u < 1/4 or u > 3/4 (n_x > 0, the image's
    # right half) and green between (the left half). Spheres compute this uv only for
    # materials that read textures (MaterialView::reads_uv), so a lost uv shows here.
    red, green = (0.8, 0.1, 0.1), (0.1, 0.8, 0.1)
    tex = np.array([[red, green, green, red]], np.float32)
    s = kauri.Scene(color_space="srgb")
    s.add_sphere(center=(0, 0, 0), radius=0.9, material=kauri.Lambert(albedo=kauri.ImageTexture(tex, wrap="repeat")))
    s.add_sphere(center=(5, 0, 0), radius=0.5, material=kauri.Lambert(albedo=(0.5, 0.5, 0.5)), name="plain")
    s.add_environment(color=(1, 1, 1))
    s.set_camera(kind="orthographic", eye=(0, 0, 5), target=(0, 0, 0), up=(0, 1, 0), width=2.0)
    img = kauri.render(s, spp=64, resolution=(32, 32), max_depth=1, seed=5).rgba[:, :, :3]
    left, right = img[13:19, 6:10].mean(axis=(0, 1)), img[13:19, 22:26].mean(axis=(0, 1))
    np.testing.assert_allclose(left, green, rtol=0.05, atol=0.01)
    np.testing.assert_allclose(right, red, rtol=0.05, atol=0.01)

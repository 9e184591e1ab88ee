"""Layered materials rendered: the course notes' figures 8–10 checked numerically,
plus the Python/JSON authoring API and its errors."""
import json
import warnings

import numpy as np
import pytest

import kauri


def uv_sphere(n_theta=48, n_phi=96, radius=1.0):
    """Tessellated sphere with smooth normals (positions, quads, normals)."""
    th = np.linspace(0, np.pi, n_theta + 1)
    ph = np.linspace(0, 2 * np.pi, n_phi + 1)
    T, P = np.meshgrid(th, ph, indexing="ij")
    N = np.stack([np.sin(T) * np.cos(P), np.cos(T), np.sin(T) * np.sin(P)], -1).reshape(-1, 3)
    idx = []
    for i in range(n_theta):
        for j in range(n_phi):
            a, b = i * (n_phi + 1) + j, (i + 1) * (n_phi + 1) + j
            idx.append([a, a + 1, b + 1, b])
    return (N * radius).astype(np.float32), np.array(idx), N.astype(np.float32)


def red_pixels(rgb):
    r, g = rgb[..., 0], rgb[..., 1]
    return int(np.sum((r > 0.1) & (g < 0.45 * r)))


@pytest.mark.parametrize("symmetric", [True, False])
def test_figure8_painted_glass_sphere(symmetric):
    # Yellow coated on red coated on clear glass; paint only on the far hemisphere.
    # Seen through the clear front, the paint's inner side is yellow with symmetric
    # shading (same stack from both sides) and red without (inverse stack: glass, red, yellow).
    P, Q, N = uv_sphere()
    stripe = (P[:, 2] < -0.2).astype(np.float32)
    m = kauri.Material("painted_glass", symmetric=symmetric)
    m.add_lobe("yellow", kauri.Lambert(albedo=(0.9, 0.8, 0.05)), weight=kauri.Attribute("paint"))
    m.add_lobe("red", kauri.Lambert(albedo=(0.8, 0.03, 0.03)), weight=kauri.Attribute("paint"))
    m.add_lobe("glass", kauri.Dielectric(ior=1.5))
    m.combine("under", "coat", "red", "glass")
    m.combine("stack", "coat", "yellow", "under")
    s = kauri.Scene(color_space="srgb")
    s.add_mesh(P, Q, normals=N, material=m, attributes={"paint": stripe}, name="ball")
    s.add_environment(color=(1, 1, 1))
    s.set_camera(eye=(0, 0, 4), target=(0, 0, 0), fov=32)
    out = kauri.render(s, spp=32, resolution=(64, 64), seed=1)
    n_red = red_pixels(out.rgba[:, :, :3])
    if symmetric:
        assert n_red == 0, f"red visible on {n_red} pixels with symmetric shading"
    else:
        assert n_red > 200, f"the back of the stack (red) should show through the glass, saw {n_red} px"


def _coated_plane(top_ior, accumulate, roughness_bottom=0.3):
    m = kauri.Material("coated", ior_accumulation=accumulate)
    m.add_lobe("top", kauri.Dielectric(ior=top_ior))
    # A dielectric-like rough reflector of IOR 1.5 (conductor with κ = 0).
    m.add_lobe("bottom", kauri.Conductor(eta=(1.5, 1.5, 1.5), k=(0, 0, 0), roughness=roughness_bottom))
    m.combine("stack", "coat", "top", "bottom")
    s = kauri.Scene()
    P = np.array([[-20, 0, -20], [20, 0, -20], [20, 0, 20], [-20, 0, 20]])
    s.add_mesh(P, np.array([[0, 3, 2, 1]]), material=m)
    # Sun at 30° from the normal; the camera looks at the origin 12° off the mirror
    # direction, where only the rough bottom lobe reflects (the top is a mirror).
    s.add_distant_light(direction=(-np.sin(np.radians(30)), -np.cos(np.radians(30)), 0), angle=1.0,
                        intensity=100)
    a = np.radians(42)
    s.set_camera(eye=(6 * np.sin(a), 6 * np.cos(a), 0), target=(0, 0, 0), fov=1)
    return s


def test_figure9_ior_accumulation_fades_the_bottom_highlight():
    iors = [1.0, 1.2, 1.35, 1.5]
    on = [kauri.render(_coated_plane(n, True), spp=64, resolution=(8, 8)).rgba[:, :, 1].mean() for n in iors]
    off = [kauri.render(_coated_plane(n, False), spp=64, resolution=(8, 8)).rgba[:, :, 1].mean() for n in iors]
    assert on[0] > 0.01
    np.testing.assert_allclose(on[0], off[0], rtol=1e-6)           # top IOR 1: nothing to accumulate
    assert all(a > b for a, b in zip(on, on[1:])), on               # fades monotonically
    assert on[-1] < 1e-3 * on[0], on                                # index-matched: gone
    assert off[-1] > 0.8 * off[0], off                              # without accumulation it stays


def _dusty_metal(top_roughness, accumulate):
    m = kauri.Material("dusty", roughness_accumulation=accumulate)
    m.add_lobe("dust", kauri.Conductor(eta=(1.5, 1.5, 1.5), k=(0, 0, 0), roughness=top_roughness), weight=0.02)
    m.add_lobe("metal", kauri.Conductor(metal="Ag", roughness=0.08))
    m.combine("stack", "coat", "dust", "metal")
    s = kauri.Scene()
    P = np.array([[-50, 0, -50], [50, 0, -50], [50, 0, 50], [-50, 0, 50]])
    s.add_mesh(P, np.array([[0, 3, 2, 1]]), material=m)
    s.add_distant_light(direction=(0, -1, 0), angle=0.5, intensity=50)
    s.set_camera(eye=(0, 4, 0.001), target=(0, 0, 0), up=(0, 0, -1), fov=90)
    return s


def highlight_width(img):
    """RMS radius (pixels) of the highlight's luminance distribution."""
    y = img[:, :, 1]
    h, w = y.shape
    yy, xx = np.mgrid[0:h, 0:w]
    t = y.sum()
    cx, cy = (xx * y).sum() / t, (yy * y).sum() / t
    return float(np.sqrt((((xx - cx) ** 2 + (yy - cy) ** 2) * y).sum() / t))


def test_figure10_roughness_accumulation_widens_the_highlight():
    widths_on = [highlight_width(kauri.render(_dusty_metal(r, True), spp=16, resolution=(48, 48)).rgba)
                 for r in (0.2, 0.35, 0.5)]
    widths_off = [highlight_width(kauri.render(_dusty_metal(r, False), spp=16, resolution=(48, 48)).rgba)
                  for r in (0.2, 0.35, 0.5)]
    assert widths_on[0] < widths_on[1] < widths_on[2], widths_on
    assert widths_on[2] > 1.5 * widths_off[2], (widths_on, widths_off)
    # Without accumulation the sharp metal highlight keeps its width.
    assert max(widths_off) < 1.25 * min(widths_off), widths_off


def test_material_api_errors_name_material_and_node():
    m = kauri.Material("paint")
    m.add_lobe("base", kauri.Lambert())
    with pytest.raises(kauri.SceneError, match=r"material 'paint', node 'base': duplicate"):
        m.add_lobe("base", kauri.Lambert())
    with pytest.raises(kauri.SceneError, match=r"material 'paint', node 'x': unknown operator 'stack'"):
        m.combine("x", "stack", "base", "base")
    with pytest.raises(kauri.SceneError, match=r"material 'paint', node 'top'.*weight.*\[0, 1\]"):
        m.add_lobe("top", kauri.Lambert(), weight=1.5)
    with pytest.raises(kauri.SceneError, match=r"material 'paint', node 'top': expected a lobe"):
        m.add_lobe("top", "lambert")
    m.add_lobe("top", kauri.Conductor(metal="Cu"))
    m.combine("stack", "coat", "top", "missing")
    s = kauri.Scene()
    with pytest.raises(ValueError, match=r"material 'paint', node 'stack': unknown input 'missing'"):
        s.add_sphere(material=m)
    cyc = kauri.Material("loop")
    cyc.add_lobe("a", kauri.Lambert())
    cyc.combine("x", "coat", "a", "y")
    cyc.combine("y", "coat", "a", "x")
    with pytest.raises(ValueError, match=r"material 'loop'.*(cycle|more than once)"):
        kauri.Scene().add_sphere(material=cyc)


def test_add_on_scattering_lobes_warns_and_coats():
    m = kauri.Material("glow")
    m.add_lobe("a", kauri.Lambert())
    m.add_lobe("b", kauri.Lambert())
    m.combine("sum", "add", "a", "b")
    s = kauri.Scene()
    with pytest.warns(UserWarning, match=r"node 'sum'.*treated as 'coat'"):
        s.add_sphere(material=m)


def test_attribute_missing_on_mesh_is_reported():
    m = kauri.Material("masked")
    m.add_lobe("a", kauri.Lambert(), weight=kauri.Attribute("mask"))
    s = kauri.Scene()
    s.add_sphere(material=m, name="ball")
    s.set_camera()
    with pytest.raises(ValueError, match=r"shape 'ball'.*material 'masked'.*attribute 'mask'"):
        kauri.render(s, spp=1, resolution=(4, 4))


def test_material_file_round_trip(tmp_path):
    doc = {"materials": [{
        "name": "car_paint", "symmetric": True,
        "lobes": [{"name": "flakes", "type": "conductor", "metal": "Al", "roughness": 0.4},
                  {"name": "clear", "type": "dielectric", "ior": 1.5, "weight": 0.9}],
        "layers": [{"name": "paint", "op": "coat", "inputs": ["clear", "flakes"]}]}]}
    path = tmp_path / "paint.json"
    path.write_text(json.dumps(doc, indent=2))
    (m,) = kauri.Material.load(str(path))
    assert m.name == "car_paint" and len(m.lobes) == 2 and m.layers[0]["op"] == "coat"
    s = kauri.Scene()
    s.add_sphere(material=m)
    bad = tmp_path / "bad.json"
    bad.write_text('{"name": "x",\n "lobes": [ {"name": "a", "type": "lambert", "albedo": 2} ]}')
    with pytest.raises(kauri.SceneError, match=r"bad.json: material 'x', node 'a'.*albedo"):
        kauri.Material.load(str(bad))
    broken = tmp_path / "broken.json"
    broken.write_text('{"name": "x",\n "lobes": [ }')
    with pytest.raises(kauri.SceneError, match=r"broken.json:2:\d+: invalid JSON"):
        kauri.Material.load(str(broken))
    unknown = tmp_path / "unknown.json"
    unknown.write_text('{"name": "x", "lobes": [{"name": "a", "type": "velvet"}]}')
    with pytest.raises(kauri.SceneError, match=r"node 'a': unknown lobe type 'velvet'"):
        kauri.Material.load(str(unknown))


def test_identical_layouts_are_shared():
    s = kauri.Scene()
    for i in range(5):
        m = kauri.Material(f"paint{i}")
        m.add_lobe("base", kauri.Lambert(albedo=(0.1 * i, 0.5, 0.5)))
        m.add_lobe("clear", kauri.Dielectric(ior=1.4 + 0.02 * i))
        m.combine("stack", "coat", "clear", "base")
        s.add_sphere(center=(2 * i, 0, 0), material=m)
    s.add_sphere(center=(0, 3, 0), material=kauri.Lambert())
    s.set_camera(eye=(4, 1, 10), target=(4, 0, 0))
    out = kauri.render(s, spp=1, resolution=(8, 8))
    assert out.stats["materials"] == 6 and out.stats["layer_layouts"] == 2


def _window(dirt_weight, view_from_front):
    m = kauri.Material("window", symmetric=False)
    m.add_lobe("dirt", kauri.Lambert(albedo=(0.2, 0.2, 0.2)), weight=dirt_weight)
    m.add_lobe("glass", kauri.ThinDielectric(ior=1.5))
    m.combine("pane", "coat", "dirt", "glass")
    s = kauri.Scene()
    s.add_mesh(np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]), np.array([[0, 1, 2, 3]]), material=m)
    s.add_environment(color=(1, 1, 1))
    z = 3 if view_from_front else -3
    s.set_camera(kind="orthographic", eye=(0, 0, z), target=(0, 0, 0), width=1.0)
    return kauri.render(s, spp=512, resolution=(8, 8), seed=3).rgba[:, :, :3].mean()


def test_dirty_window_front_and_back_differ_only_by_the_dirt():
    # Thin glass at normal incidence: R' = 2R/(1+R), R = ((n−1)/(n+1))², T' = 1 − R'.
    R = (0.5 / 2.5) ** 2
    Rp = 2 * R / (1 + R)
    w, rho = 0.4, 0.2
    # Clean: the same from both sides (R' + T' = 1 in a white furnace).
    np.testing.assert_allclose(_window(0.0, True), 1.0, rtol=0.01)
    np.testing.assert_allclose(_window(0.0, False), 1.0, rtol=0.01)
    # Dirty side in front: dirt on top (w ρ), the glass gets the rest (1 − w)(R' + T').
    np.testing.assert_allclose(_window(w, True), w * rho + (1 - w), rtol=0.01)
    # From behind: glass on top; it passes T' on to the dirt where the dirt is present
    # and transmits the rest: R' + (1 − w) T' + w (1 − R') ρ.
    np.testing.assert_allclose(_window(w, False), Rp + (1 - w) * (1 - Rp) + w * (1 - Rp) * rho, rtol=0.01)


AP1_Y = np.array([0.2722287, 0.6740818, 0.0536895])


def _panel_view(material, camera_dir=(0, 0, 1), spp=64):
    """Camera looking straight at a panel facing +z, nothing else in the scene."""
    s = kauri.Scene()
    s.add_mesh(np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]), np.array([[0, 1, 2, 3]]), material=material)
    d = np.asarray(camera_dir, float)
    s.set_camera(kind="orthographic", eye=tuple(3 * d / np.linalg.norm(d)), target=(0, 0, 0), width=0.2)
    return kauri.render(s, spp=spp, resolution=(4, 4), seed=2).rgba[:, :, :3].reshape(-1, 3).mean(axis=0)


def test_add_of_emission_adds():
    m = kauri.Material("lamp")
    m.add_lobe("a", kauri.EmissionLobe(intensity=1.0))
    m.add_lobe("b", kauri.EmissionLobe(intensity=2.0))
    m.combine("both", "add", "a", "b")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # emission-only add is legal: no warning
        rgb = _panel_view(m)
    np.testing.assert_allclose(rgb, 3.0, rtol=0.01)  # spectral noise only


def test_varnish_over_emission_dims_it_by_the_transmitted_energy():
    m = kauri.Material("glowing_varnish")
    m.add_lobe("varnish", kauri.Dielectric(ior=1.5))
    m.add_lobe("glow", kauri.EmissionLobe(intensity=2.0))
    m.combine("stack", "coat", "varnish", "glow")
    np.testing.assert_allclose(_panel_view(m), 2.0 * (1 - 0.04), rtol=0.01)


def test_focused_emission_keeps_exitance_and_peaks_on_axis():
    n = 8.0
    on_axis = _panel_view(kauri.Material("spot").add_lobe("e", kauri.EmissionLobe(focus=n)))
    np.testing.assert_allclose(on_axis, (n + 2) / 2, rtol=0.01)
    c = np.cos(np.radians(40))
    off = _panel_view(kauri.Material("spot").add_lobe("e", kauri.EmissionLobe(focus=n)),
                      camera_dir=(np.sin(np.radians(40)), 0, c))
    np.testing.assert_allclose(off, (n + 2) / 2 * c ** n, rtol=0.01)


def test_emissive_material_lights_the_scene_like_shape_emission():
    def probe(use_material):
        s = kauri.Scene()
        P = np.array([[-20, 0, -20], [20, 0, -20], [20, 0, 20], [-20, 0, 20]])
        s.add_mesh(P, np.array([[0, 3, 2, 1]]), material=kauri.Lambert(albedo=(0.5, 0.5, 0.5)))
        lamp = np.array([[-0.5, 1, -0.5], [0.5, 1, -0.5], [0.5, 1, 0.5], [-0.5, 1, 0.5]])
        if use_material:
            m = kauri.Material("lamp_material")
            m.add_lobe("e", kauri.EmissionLobe(intensity=4.0, temperature=4000))
            s.add_mesh(lamp, np.array([[0, 1, 2, 3]]), material=m)
        else:
            s.add_mesh(lamp, np.array([[0, 1, 2, 3]]), emission=kauri.Emission(intensity=4.0, temperature=4000))
        s.set_camera(kind="orthographic", eye=(0, 0.5, 0), target=(0, 0, 0), up=(0, 0, -1), width=0.01)
        return kauri.render(s, spp=1024, resolution=(4, 4), seed=4).rgba[:, :, :3].reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(probe(True), probe(False), rtol=0.01)


def test_tabulated_spectral_emission():
    # A flat tabulated spectrum of value v has luminance Y = v.
    flat = [(350.0, 2.0), (850.0, 2.0)]
    rgb = _panel_view(kauri.Material("flat").add_lobe("e", kauri.EmissionLobe(spectrum=flat)), spp=256)
    np.testing.assert_allclose(rgb @ AP1_Y, 2.0, rtol=0.01)
    with pytest.raises(ValueError, match=r"spectrum.*increase"):
        kauri.Scene().add_sphere(material=kauri.Material("bad").add_lobe(
            "e", kauri.EmissionLobe(spectrum=[(500, 1), (400, 1)])))

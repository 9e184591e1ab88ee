"""Glossy spheres (single-scattering GGX: rough gold at two roughnesses and a rough glass)
on a diffuse floor under a constant sky and an area light. Mitsuba's roughconductor /
roughdielectric have no multiple-scattering term, so kauri renders the matching
uncompensated lobes (ggx_conductor@1, ggx_dielectric@1)."""


def describe():
    return {
        "name": "glossy",
        "color_space": "srgb",
        "shapes": [
            {"name": "floor", "quad": [(-6, 0, 6), (6, 0, 6), (6, 0, -6), (-6, 0, -6)], "diffuse": (0.4, 0.4, 0.4)},
            {"name": "gold_sharp", "sphere": ((-1.6, 0.7, 0), 0.7), "conductor": {"metal": "Au", "alpha": 0.05}},
            {"name": "gold_rough", "sphere": ((0.0, 0.7, 0), 0.7), "conductor": {"metal": "Au", "alpha": 0.3}},
            {"name": "glass", "sphere": ((1.6, 0.7, 0), 0.7), "dielectric": {"ior": 1.5, "alpha": 0.15}},
            {"name": "panel", "quad": [(-1, 3, -1), (1, 3, -1), (1, 3, 1), (-1, 3, 1)], "emission": (6.0, 6.0, 6.0)},
        ],
        "environment_color": (0.4, 0.45, 0.5),
        "camera": {"eye": (0, 2.2, 5.5), "target": (0, 0.6, 0), "up": (0, 1, 0), "fov_x": 50.0},
    }

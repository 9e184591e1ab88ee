"""Many small lights, like the hangar of the course notes: a 12 × 12 grid of small one-sided
ceiling panels of varying colour over a diffuse floor with a few boxes (quads only)."""


def describe(n=12):
    shapes = [{"name": "floor", "quad": [(-8, 0, 8), (8, 0, 8), (8, 0, -8), (-8, 0, -8)], "diffuse": (0.5, 0.5, 0.5)},
              {"name": "back", "quad": [(-8, 0, -8), (8, 0, -8), (8, 6, -8), (-8, 6, -8)], "diffuse": (0.6, 0.55, 0.5)}]
    for i in range(3):  # three crates, front faces only
        x = -4 + 4 * i
        shapes.append({"name": f"crate{i}", "quad": [(x - 1, 0, 1), (x + 1, 0, 1), (x + 1, 2, 1), (x - 1, 2, 1)],
                       "diffuse": (0.7, 0.4 + 0.1 * i, 0.2)})
    s, half = 14.0 / n, 0.12
    for i in range(n):
        for j in range(n):
            x, z = -7 + s * (i + 0.5), -7 + s * (j + 0.5)
            warm = (i + j) % 3
            col = [(9.0, 7.5, 5.0), (6.0, 7.0, 9.0), (8.0, 8.0, 8.0)][warm]
            shapes.append({"name": f"lamp_{i}_{j}", "emission": col,
                           "quad": [(x - half, 5.5, z - half), (x + half, 5.5, z - half), (x + half, 5.5, z + half),
                                    (x - half, 5.5, z + half)]})
    return {"name": "hangar", "color_space": "srgb", "shapes": shapes,
            "camera": {"eye": (0, 3, 9), "target": (0, 1.5, 0), "up": (0, 1, 0), "fov_x": 70.0}}

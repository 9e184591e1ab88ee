"""A Cornell box in a neutral description: plain data that bench/peers.py turns into a
kauri scene and a Mitsuba 3 scene. Linear sRGB colours; one-sided quad light facing down."""


def quad(a, b, c, d):
    return [a, b, c, d]


def describe():
    white, red, green = (0.73, 0.73, 0.73), (0.63, 0.065, 0.05), (0.14, 0.45, 0.091)
    return {
        "name": "cornell",
        "color_space": "srgb",
        "shapes": [
            {"name": "floor", "quad": quad((-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)), "diffuse": white},
            {"name": "ceiling", "quad": quad((-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)), "diffuse": white},
            {"name": "back", "quad": quad((-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)), "diffuse": white},
            {"name": "left", "quad": quad((-1, 0, 1), (-1, 0, -1), (-1, 2, -1), (-1, 2, 1)), "diffuse": red},
            {"name": "right", "quad": quad((1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)), "diffuse": green},
            {"name": "light", "quad": quad((-0.25, 1.99, -0.25), (0.25, 1.99, -0.25), (0.25, 1.99, 0.25),
                                            (-0.25, 1.99, 0.25)),
             "emission": (17.0, 17.0, 17.0)},
        ],
        "camera": {"eye": (0, 1, 3.85), "target": (0, 1, 0), "up": (0, 1, 0), "fov_x": 38.0},
    }

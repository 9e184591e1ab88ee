"""White furnace: grey spheres in a uniform environment of radiance 1.

Every sphere should render exactly its albedo; `kauri render scenes/furnace.py`.
"""
import kauri


def build():
    s = kauri.Scene()
    for i, rho in enumerate([0.2, 0.5, 0.8, 1.0]):
        s.add_sphere(center=(-3 + 2 * i, 0, 0), radius=0.9, material=kauri.Lambert(albedo=(rho, rho, rho)),
                     name=f"lambert_{rho}")
    s.add_environment(color=(1, 1, 1))
    s.set_camera(eye=(0, 0, 9), target=(0, 0, 0), fov=50)
    return s

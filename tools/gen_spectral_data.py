#!/usr/bin/env python3
"""Generate src/kauri/spectral/data/spectral_tables.cpp (dev-time tool; the output is committed).

Usage:  python3 tools/gen_spectral_data.py [DATA_DIR]
        DATA_DIR defaults to ../shared/data relative to the repository root.

Inputs
  * DATA_DIR/spectral/cie/CIE_xyz_1931_2deg.csv   CIE 1931 2 deg CMFs, 1 nm, 360..830
  * DATA_DIR/spectral/cie/CIE_std_illum_D65.csv   CIE D65 SPD, 1 nm, 300..830
  * DATA_DIR/spectral/metal-ior/<M>.eta.spd, <M>.k.spd   complex IOR (wavelength nm, value)
  * colour-science (python package): ACES D60 = CIE daylight at xy (0.32168, 0.33767)
    (SMPTE ST 2065-1 white), built with colour.sd_CIE_illuminant_D_series from the CIE
    S0/S1/S2 basis at 5 nm and linearly interpolated to 1 nm (CIE 15 recommends linear
    interpolation of the daylight basis).

Outputs (all float):
  * 1 nm grid 360..830 (471 samples): kCieX, kCieY, kCieZ, kCieD65, kAcesD60, and
    kCieYIntegral = sum of ybar over the 1 nm table (the "CIE_Y_integral" normaliser).
  * 5 nm grid 360..830 (95 samples): eta and k of the metals listed in METALS, linearly
    resampled from the irregular source grids (measured data has ~10-30 nm spacing, so 5 nm
    loses nothing and keeps the file small).
"""
import csv
import os
import sys
import warnings

import numpy as np

LAMBDA_MIN, LAMBDA_MAX = 360, 830
GRID_1NM = np.arange(LAMBDA_MIN, LAMBDA_MAX + 1, 1.0)
METAL_STEP = 5
GRID_METAL = np.arange(LAMBDA_MIN, LAMBDA_MAX + 1, METAL_STEP, dtype=float)
# Requested set: Au, Ag, Cu, Al, Cr, Fe, Ti. Only those present in the data folder are emitted
# (Fe and Ti are not in mitsuba-data's metal-ior set; the generator reports what it skipped).
METALS = ["Au", "Ag", "Cu", "Al", "Cr", "Fe", "Ti"]
ACES_D60_XY = (0.32168, 0.33767)


def repo_root():
    return os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_csv_columns(path):
    """Numeric rows of a CSV with one header line -> 2-D array."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return np.array([[float(v) for v in r] for r in rows[1:] if r], dtype=float)


def on_1nm_grid(table, column):
    """Exact 1 nm samples 360..830 of `column`; refuses to interpolate silently."""
    lam = table[:, 0]
    out = np.interp(GRID_1NM, lam, table[:, column])
    if not np.all(np.isin(GRID_1NM, lam)):
        raise SystemExit("expected integer-nm samples covering 360..830")
    return out


def read_spd(path):
    data = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                lam, val = line.split()[:2]
                data.append((float(lam), float(val)))
    data = np.array(sorted(data))
    if data[0, 0] > LAMBDA_MIN or data[-1, 0] < LAMBDA_MAX:
        raise SystemExit(f"{path}: does not cover {LAMBDA_MIN}..{LAMBDA_MAX} nm")
    return data


def aces_d60():
    warnings.filterwarnings("ignore")  # colour warns about missing matplotlib
    import colour

    sd = colour.sd_CIE_illuminant_D_series(np.array(ACES_D60_XY))
    lam = np.asarray(sd.wavelengths, dtype=float)
    return np.interp(GRID_1NM, lam, np.asarray(sd.values, dtype=float)), colour.__version__


def fmt_float(v):
    """C++ float literal; 9 significant digits round-trip any float32."""
    s = f"{v:.9g}"
    return (s if any(ch in s for ch in ".en") else s + ".0") + "f"


def fmt_array(name, values, per_line=8):
    vals = [fmt_float(v) for v in values]
    lines = [", ".join(vals[i:i + per_line]) for i in range(0, len(vals), per_line)]
    body = ",\n    ".join(lines)
    return f"const float {name}[{len(values)}] = {{\n    {body}}};\n"


def main():
    data_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(repo_root(), "..", "shared", "data")
    data_dir = os.path.abspath(data_dir)
    cie_dir = os.path.join(data_dir, "spectral", "cie")
    metal_dir = os.path.join(data_dir, "spectral", "metal-ior")

    cmf = read_csv_columns(os.path.join(cie_dir, "CIE_xyz_1931_2deg.csv"))
    x, y, z = (on_1nm_grid(cmf, c) for c in (1, 2, 3))
    d65 = on_1nm_grid(read_csv_columns(os.path.join(cie_dir, "CIE_std_illum_D65.csv")), 1)
    d60, colour_version = aces_d60()
    y_integral = float(np.sum(y.astype(np.float32).astype(np.float64)))

    metals = []
    for m in METALS:
        eta_path = os.path.join(metal_dir, f"{m}.eta.spd")
        k_path = os.path.join(metal_dir, f"{m}.k.spd")
        if not (os.path.exists(eta_path) and os.path.exists(k_path)):
            print(f"note: no IOR data for {m} in {metal_dir}; skipped", file=sys.stderr)
            continue
        eta, k = read_spd(eta_path), read_spd(k_path)
        metals.append((m, np.interp(GRID_METAL, eta[:, 0], eta[:, 1]),
                       np.interp(GRID_METAL, k[:, 0], k[:, 1])))

    out = []
    out.append("// GENERATED FILE - DO NOT EDIT. Regenerate with: python3 tools/gen_spectral_data.py\n")
    out.append("//\n// Sources:\n")
    out.append("//   CIE 1931 2 deg CMFs: shared/data/spectral/cie/CIE_xyz_1931_2deg.csv (CIE, CC BY-SA 4.0)\n")
    out.append("//   CIE D65 SPD:        shared/data/spectral/cie/CIE_std_illum_D65.csv (CIE, CC BY-SA 4.0)\n")
    out.append(f"//   ACES D60 SPD:       colour-science {colour_version}, sd_CIE_illuminant_D_series at xy "
               f"{ACES_D60_XY}, linear to 1 nm\n")
    out.append("//   Metal IOR:          shared/data/spectral/metal-ior/<M>.{eta,k}.spd "
               "(mitsuba-data @ 01100fa9; luxpop/Palik), linear to 5 nm\n")
    out.append("#include \"kauri/spectral/spectral_tables.h\"\n\nnamespace kauri::tables {\n\n")
    out.append(f"const float kCieYIntegral = {fmt_float(y_integral)};  // sum of kCieY (1 nm steps)\n\n")
    for name, arr in (("kCieX", x), ("kCieY", y), ("kCieZ", z), ("kCieD65", d65), ("kAcesD60", d60)):
        out.append(fmt_array(name, arr))
        out.append("\n")
    for m, eta, k in metals:
        out.append(fmt_array(f"k{m}Eta", eta))
        out.append(fmt_array(f"k{m}K", k))
        out.append("\n")
    out.append(f"const MetalIOR kMetals[{len(metals)}] = {{\n")
    for m, _, _ in metals:
        out.append(f"    {{\"{m}\", k{m}Eta, k{m}K}},\n")
    out.append("};\n")
    out.append(f"const int kMetalCount = {len(metals)};\n\n}}  // namespace kauri::tables\n")

    path = os.path.join(repo_root(), "src", "kauri", "spectral", "data", "spectral_tables.cpp")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("".join(out))
    os.replace(tmp, path)
    print(f"wrote {path} (CIE_Y_integral = {y_integral:.6f}, metals: {[m for m, _, _ in metals]})")


if __name__ == "__main__":
    main()

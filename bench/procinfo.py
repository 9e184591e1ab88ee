"""Process facts shared by the suite's workers and the Cycles peer (plain Python: it runs
under both the suite's and the bpy environment's interpreters)."""


def vmhwm_kib():
    """This process's own high-water RSS in KiB from /proc/self/status (cross-check of
    wait4's ru_maxrss), or None where there is no /proc."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None

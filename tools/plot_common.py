"""What tools/plot_bench.py and tools/plot_accuracy.py share: the one-line user error and a reproducible
matplotlib (SVG labels kept as text, stable ids so that the same input writes the same file)."""


class PlotError(Exception):
    """A one-line error for the user."""


def pyplot():
    """matplotlib with the Agg backend and reproducible SVG output, and its pyplot; PlotError if not installed."""
    import sys
    try:
        import matplotlib
        matplotlib.use("Agg")
        from matplotlib import pyplot as plt
    except ImportError:
        raise PlotError("matplotlib is not installed for %s (Debian's python3-matplotlib, from "
                        "tools/install_deps.sh, is for /usr/bin/python3)" % sys.executable)
    matplotlib.rcParams["svg.fonttype"] = "none"  # labels stay text: searchable, smaller
    matplotlib.rcParams["svg.hashsalt"] = "phiq"  # stable ids: the same input writes the same file
    return matplotlib, plt

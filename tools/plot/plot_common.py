"""What tools/plot/plot_bench.py and tools/plot/plot_accuracy.py share: the one-line user error and a reproducible
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


def save(fig, svg, png=None, svg_dpi=72, png_dpi=110):
    """Writes the figure as SVG (no date: the same input writes the same file) and, if asked, PNG."""
    for path, form in [(svg, "svg")] + ([(png, "png")] if png else []):
        try:
            fig.savefig(path, format=form, metadata={"Date": None} if form == "svg" else None,
                        dpi=svg_dpi if form == "svg" else png_dpi)
        except OSError as e:
            raise PlotError("%s: cannot write: %s" % (path, e.strerror or e))


def run(main, prog, argv):
    """main(argv), with a PlotError printed as one line on stderr and exit status 1."""
    import sys
    try:
        return main(argv)
    except PlotError as e:
        print("%s: %s" % (prog, e), file=sys.stderr)
        return 1

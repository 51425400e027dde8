"""Shared helpers of Orrery's plotting scripts (tools/plot).

The scripts draw what the `orrery` commands computed and handed over in a JSON file (or, for
recorded series, what a result file holds), as PNG files for a person to read: a title, labelled
axes with units. They need Debian's python3-matplotlib and python3-numpy (python3-h5py for the
scripts that read result files); a missing module ends the script with one line naming the
package, exit status 3.
"""
import json
import sys

PACKAGES = "python3-matplotlib python3-numpy python3-h5py"


def fail(message, status=2):
    """One line on stderr, then exit."""
    print("orrery plot: error: " + " ".join(str(message).split()), file=sys.stderr)
    sys.exit(status)


def pyplot():
    """matplotlib.pyplot on the Agg backend (no display needed)."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy  # noqa: F401  (matplotlib needs it; say so by name when missing)
    except ImportError as e:
        fail(f"{e}: install Debian's {PACKAGES} (tools/install_deps.sh)", 3)
    return plt


def h5py_module():
    try:
        import h5py
    except ImportError as e:
        fail(f"{e}: install Debian's {PACKAGES} (tools/install_deps.sh)", 3)
    return h5py


def load_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{path}: {e}")


def save(fig, path):
    try:
        fig.savefig(path, dpi=120)
    except (OSError, ValueError) as e:
        fail(f"{path}: {e}")


def finite(values):
    """None (JSON null) as NaN."""
    return [float("nan") if v is None else v for v in values]


def positive_floor(values):
    """A floor for a logarithmic axis: 1e-8 of the largest positive value."""
    top = max((v for v in values if v is not None and v > 0), default=1.0)
    return top * 1e-8

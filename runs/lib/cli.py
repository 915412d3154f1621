"""The command line of a case script: argparse with the script's docstring as its help, so that
a misspelt option is an error."""
import argparse


def parser(doc, short=True):
    """An ArgumentParser showing DOC; with short, the `--short` option every case has (the
    quick version the test suite runs)."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    if short:
        p.add_argument("--short", action="store_true", help="the short version (./fsi test)")
    return p


def body_viscosity(p, what):
    """The --body-viscosity option of a case whose runs WHAT ([fluid] body_viscosity written
    into its scenes; not given: the fluid's default, "none")."""
    p.add_argument("--body-viscosity", choices=("none", "kelvin-voigt"), default=None,
                   help=f"[fluid] body_viscosity of {what} (default: not written, the fluid's "
                        "none; the README's tables measured before it became the default are "
                        "kelvin-voigt), outputs under OUT/.../body-viscosity-X")


def body_divergence(p, what):
    """The --body-divergence option of a case whose runs WHAT ([fluid] body_divergence written
    into its scenes; not given: the fluid's default)."""
    p.add_argument("--body-divergence", choices=("solid", "zero", "coupled_step"), default=None,
                   help=f"[fluid] body_divergence of {what} (default: not written, the fluid's "
                        "own), outputs under OUT/.../body-divergence-X")


def interface(p, what):
    """The --interface option of a case whose runs WHAT ([fluid] interface written into its
    scenes; not given: the fluid's default, "volume", Eq. 21)."""
    p.add_argument("--interface", choices=("volume", "sharp"), default=None,
                   help=f"[fluid] interface of {what} (default: not written, the fluid's volume), "
                        "outputs under OUT/.../interface-X")


def implicit_forcing(p, what):
    """The --implicit-forcing option of a case whose runs WHAT with Crank-Nicolson ([fluid]
    implicit_forcing written into its scenes; not given: the fluid's default, "increment")."""
    p.add_argument("--implicit-forcing", choices=("increment", "after_solve"), default=None,
                   help=f"[fluid] implicit_forcing of {what} (default: not written, the fluid's "
                        "increment; the tables measured before it became the default are "
                        "after_solve), outputs under OUT/.../implicit-forcing-X")


def ints(text):
    """A comma-separated list of integers, for `type=`."""
    try:
        return [int(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"a comma-separated list of integers, got '{text}'")


def positive(text):
    """A number > 0, for `type=`."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a number, got '{text}'")
    if not v > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return v


def count(text):
    """An integer >= 0, for `type=`."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"an integer, got '{text}'")
    if v < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text}")
    return v

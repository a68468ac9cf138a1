"""landnav: synthetic land-vehicle drives and navigation-sensor datasets (the ``simulator``
package; the command line is ``simulator.cli``)."""

__version__ = "0.1.0"

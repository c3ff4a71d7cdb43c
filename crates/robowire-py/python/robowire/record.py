"""MCAP captures of robowire's links, for Foxglove, ``robowire replay`` and any MCAP reader.

Every client and simulator takes ``record=``: a path (the object records into a file of its own
and finishes it when it is closed) or a :class:`Recorder` (several devices into one file; close
the recorder after them). Each link is written both ways as it was on the wire (raw, or CDR for
DDS) and, beside it, as JSON with a JSON schema. Links are named as ``robowire … --record`` names
them: ``kmc/serial`` (and ``kmc/serial_skipped``), ``zsl1/high_level``, ``zsl1/low_level``,
``go2/low_level``, ``go2/api``, ``hg/…``, ``spline/spline``, ``spline/imu``.

>>> import os, tempfile
>>> import robowire
>>> path = os.path.join(tempfile.mkdtemp(), "chassis.mcap")
>>> with robowire.Recorder(path, compression="zstd") as rec:
...     with robowire.open("sim:kmc", record=rec) as chassis:
...         chassis.wait_state(timeout_s=5.0)
True
>>> summary = rec.close()                      # closed already: the same summary again
>>> summary["frames"] > 0, summary["dropped"]
(True, 0)
"""

from ._native import Recorder

__all__ = ["Recorder"]

"""Unitree's low-level messages, Go2 (``unitree_go``) and HG (``unitree_hg``: G1, H1-2), as
objects with the IDL field names.

Fields are attributes (``cmd.motor_cmd[3].q = 0.5``; nested structs and arrays are live views
into the message), or all at once with :meth:`LowCmd.from_dict` / :meth:`LowCmd.to_dict`, whose
shape is exactly what ``robowire decode lowcmd --json`` prints and ``robowire encode lowcmd``
reads. ``encode()`` gives the struct image the firmware checks (padding zeroed, CRC written);
``encode_cdr()`` the DDS payload; ``decode()``/``decode_cdr()`` verify the CRC and raise
:class:`robowire.CrcError` with both CRCs on a mismatch.

>>> from robowire.unitree import LowCmd
>>> cmd = LowCmd(head=[0xFE, 0xEF], level_flag=0xFF)
>>> cmd.motor_cmd[0].q = 0.5
>>> data = cmd.encode()
>>> LowCmd.decode(data).motor_cmd[0].q
0.5
"""

from ._native import ArrayView, HgLowCmd, HgLowState, LowCmd, LowState, StructView

__all__ = ["LowCmd", "LowState", "HgLowCmd", "HgLowState", "StructView", "ArrayView"]

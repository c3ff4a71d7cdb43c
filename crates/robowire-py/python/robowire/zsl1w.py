"""A drop-in for ZsiBot's ZSL-1W (wheel-legged) module ``mc_sdk_zsl_1w_py``.

``import robowire.zsl1w as mc_sdk_zsl_1w_py``: the vendor's ``HighLevel`` with crawl, climb and
the foot/wheel joints; commands carry the ZSL-1W magic 0x5AA6. The differences from the
vendor's module are those of :mod:`robowire.zsl1`.
"""

from ._native import Zsl1wHighLevel as HighLevel

__all__ = ["HighLevel"]

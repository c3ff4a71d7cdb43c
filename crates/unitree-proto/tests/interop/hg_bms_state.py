"""Unitree's own IDL class of the HG BmsState_ (cyclonedds' serializer): a sample with a distinct
value in every field, serialized in XCDR1 and XCDR2, printed as one JSON line for
tests/it/hg_bms_state.rs."""
import json
import sys

from unitree_sdk2py.idl.unitree_hg.msg.dds_ import BmsState_

fields = dict(
    version_high=1,
    version_low=2,
    fn=3,
    cell_vol=[3300 + i for i in range(40)],
    bmsvoltage=[50000, 50001, 50002],
    current=-2345,
    soc=87,
    soh=99,
    temperature=[20 + i for i in range(12)],
    cycle=321,
    manufacturer_date=0x2405,
    bmsstate=[1, 2, 3, 4, 5],
    reserve=[6, 7, 8],
)
sample = BmsState_(**fields)
out = {"fields": fields, "xcdr1": sample.serialize().hex()}
try:
    out["xcdr2"] = sample.serialize(use_version_2=True).hex()
except TypeError as e:  # an older binding without the switch
    print(f"no XCDR2 switch: {e}", file=sys.stderr)
print(json.dumps(out))

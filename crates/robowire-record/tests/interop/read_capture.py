"""Reads a robowire capture with the `mcap` Python package, an MCAP reader independent of
robowire's, and prints what it found as one JSON line (for robowire-record's tests, and the
`robowire` crate's tests of the captures its commands' `--record` makes).

    python read_capture.py FILE.mcap

Per channel: topic, message encoding, schema name and encoding, count, whether log times are
monotonic, how many JSON messages parse; for `cdr` channels with an `omgidl` schema of a Unitree
type, how many deserialise with Unitree's own IDL classes (`unitree_sdk2py`, on cyclonedds) and
how many of those carry the CRC Unitree's `crc.py` computes (LowCmd_/LowState_); the `robowire`
metadata record.
"""

import json
import sys

from mcap.reader import make_reader


def unitree_types():
    """Unitree's IDL classes by the scoped name robowire's schemas carry, and their CRC (or
    None where the SDK is not importable: the counts then stay 0)."""
    try:
        from unitree_sdk2py.idl.unitree_api.msg.dds_ import Request_, Response_
        from unitree_sdk2py.idl.unitree_go.msg.dds_ import LowCmd_, LowState_
        from unitree_sdk2py.idl.unitree_hg.msg.dds_ import LowCmd_ as HgLowCmd_
        from unitree_sdk2py.idl.unitree_hg.msg.dds_ import LowState_ as HgLowState_
        from unitree_sdk2py.utils.crc import CRC
    except ImportError:
        return {}, None
    types = {
        "unitree_go::msg::dds_::LowCmd_": LowCmd_,
        "unitree_go::msg::dds_::LowState_": LowState_,
        "unitree_hg::msg::dds_::LowCmd_": HgLowCmd_,
        "unitree_hg::msg::dds_::LowState_": HgLowState_,
        "unitree_api::msg::dds_::Request_": Request_,
        "unitree_api::msg::dds_::Response_": Response_,
    }
    return types, CRC()


def main():
    types, crc = unitree_types()
    with open(sys.argv[1], "rb") as f:
        reader = make_reader(f)
        channels = {}
        for schema, channel, message in reader.iter_messages():
            c = channels.setdefault(
                channel.topic,
                {
                    "encoding": channel.message_encoding,
                    "schema": schema.name if schema else None,
                    "schema_encoding": schema.encoding if schema else None,
                    "schema_parses": bool(schema and schema.encoding == "jsonschema" and json.loads(schema.data)),
                    "schema_text": schema.data.decode() if schema and schema.encoding == "omgidl" else None,
                    "metadata": dict(channel.metadata),
                    "count": 0,
                    "monotonic": True,
                    "json_ok": 0,
                    "cdr_ok": 0,
                    "crc_ok": 0,
                    "last": 0,
                },
            )
            c["count"] += 1
            if message.log_time < c["last"]:
                c["monotonic"] = False
            c["last"] = message.log_time
            if channel.message_encoding == "json":
                json.loads(message.data)
                c["json_ok"] += 1
            elif channel.message_encoding == "cdr" and schema and schema.name in types:
                sample = types[schema.name].deserialize(message.data)
                c["cdr_ok"] += 1
                if hasattr(sample, "crc") and crc.Crc(sample) == sample.crc:
                    c["crc_ok"] += 1
        f.seek(0)
        metadata = {m.name: dict(m.metadata) for m in make_reader(f).iter_metadata()}
    for c in channels.values():
        c.pop("last")
    print(json.dumps({"channels": channels, "metadata": metadata, "unitree_types": bool(types)}))


if __name__ == "__main__":
    main()

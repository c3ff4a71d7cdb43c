"""Reads a robowire capture with the `mcap` Python package, an MCAP reader independent of
robowire's, and prints what it found as one JSON line.

    python read_capture.py FILE.mcap

Per channel: topic, message encoding, schema name and encoding, count, whether log times are
monotonic, how many JSON messages parse; the `robowire` metadata record.
"""

import json
import sys

from mcap.reader import make_reader


def main():
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
                    "schema_parses": bool(schema and json.loads(schema.data)),
                    "metadata": dict(channel.metadata),
                    "count": 0,
                    "monotonic": True,
                    "json_ok": 0,
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
        f.seek(0)
        metadata = {m.name: dict(m.metadata) for m in make_reader(f).iter_metadata()}
    print(json.dumps({"channels": channels, "metadata": metadata}))


if __name__ == "__main__":
    main()

"""A CycloneDDS participant (the `cyclonedds` Python binding, Unitree's IDL classes and CRC) as the
other end of robowire-dds's interoperability tests (`tests/cyclone.rs`). Each scenario prints
JSON lines on stdout (one object a line, an "event" in each) and reads words on stdin ("go",
"quit") where robowire's side has to say when. Every wait has a deadline; a scenario that misses one
prints {"event": "error", ...} and exits 1.

Usage: python peer.py SCENARIO [ARGS...]   (on `lo`, domain 0)

  discovery                 USER_DATA "cyclone=peer;" on its participant, a LowState writer and a
                            LowCmd reader; lists what the builtin topics DCPSParticipant,
                            DCPSPublication and DCPSSubscription show of others until it has a
                            participant with USER_DATA "enclave=/;" and a writer and a reader of
                            it ("discovered"), then waits for "quit".
  stream QOS COUNT          QOS reliable|best_effort. A Go2 LowCmd reader and LowState writer;
                            "matched" once both are matched, then on "go" writes COUNT LowStates
                            (tick 1..COUNT, Unitree's CRC) while it takes LowCmds (CRC checked by
                            Unitree's code) until it has COUNT or "quit"; "summary".
  fragments COUNT           the same, reliable, with HG LowStates (2092 bytes) both ways on
                            rt/lowstate.
  late_writer COUNT         a transient-local Go2 LowState writer (keep last COUNT) writes COUNT
                            samples ("written") and waits for "quit".
  late_reader COUNT         a transient-local reliable Go2 LowState reader made now; "summary"
                            once it has COUNT samples.
  incompatible              a reliable LowCmd reader and a best-effort LowState writer; reports
                            their incompatible-QoS statuses ("incompatible") and waits for "quit".
  heartbeat                 a Go2 LowState writer (reliable) every 10 ms and a LowCmd reader;
                            "receiving" once it has LowCmds; until "quit".
"""
import importlib.metadata
import json
import os
import queue
import sys
import threading
import time

os.environ.setdefault(
    "CYCLONEDDS_URI",
    "<CycloneDDS><Domain Id=\"any\"><General><Interfaces>"
    "<NetworkInterface name=\"lo\" priority=\"default\" multicast=\"default\"/>"
    "</Interfaces></General></Domain></CycloneDDS>",
)

import cyclonedds.__library__ as library  # noqa: E402
from cyclonedds.builtin import (  # noqa: E402
    BuiltinDataReader,
    BuiltinTopicDcpsParticipant,
    BuiltinTopicDcpsPublication,
    BuiltinTopicDcpsSubscription,
)
from cyclonedds.core import Listener, Policy, Qos  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from unitree_sdk2py.idl.default import (  # noqa: E402
    unitree_go_msg_dds__LowState_,
    unitree_hg_msg_dds__LowState_,
)
from unitree_sdk2py.idl.unitree_go.msg.dds_ import LowCmd_, LowState_  # noqa: E402
from unitree_sdk2py.idl.unitree_hg.msg.dds_ import LowState_ as HgLowState_  # noqa: E402
from unitree_sdk2py.utils.crc import CRC  # noqa: E402

DEADLINE_S = 30.0
USER_DATA = b"cyclone=peer;"
crc = CRC()


def say(event, **fields):
    print(json.dumps({"event": event, **fields}), flush=True)


def fail(why, **fields):
    say("error", why=why, **fields)
    sys.exit(1)


# stdin's words, as they come (EOF: "quit").
words = queue.Queue()


def _read_stdin():
    for line in sys.stdin:
        words.put(line.strip())
    words.put("quit")


threading.Thread(target=_read_stdin, daemon=True).start()


def wait_word(word, deadline=DEADLINE_S):
    try:
        got = words.get(timeout=deadline)
    except queue.Empty:
        fail(f"no {word!r} on stdin within {deadline} s")
    if got != word and got != "quit":
        fail(f"expected {word!r} on stdin, got {got!r}")
    return got


def heard(word):
    try:
        return words.get_nowait() == word
    except queue.Empty:
        return False


def until(condition, what, deadline=DEADLINE_S):
    end = time.time() + deadline
    while not condition():
        if time.time() > end:
            fail(f"{what} within {deadline} s")
        time.sleep(0.005)


def reliability(name):
    if name == "reliable":
        return Policy.Reliability.Reliable(max_blocking_time=100_000_000)
    if name == "best_effort":
        return Policy.Reliability.BestEffort
    fail(f"unknown reliability {name}")


class Watch:
    """An endpoint's statuses as its listener reports them (the binding 0.10.2 has no getters)."""

    def __init__(self):
        self.lock = threading.Lock()
        self.matched = 0
        self.incompatible = []  # [total_count, last_policy_id]
        self.listener = Listener(
            on_publication_matched=self._matched,
            on_subscription_matched=self._matched,
            on_offered_incompatible_qos=self._incompatible,
            on_requested_incompatible_qos=self._incompatible,
        )

    def _matched(self, _entity, status):
        with self.lock:
            self.matched = status.current_count

    def _incompatible(self, _entity, status):
        with self.lock:
            self.incompatible.append([status.total_count, status.last_policy_id])

    def get(self):
        with self.lock:
            return self.matched, list(self.incompatible)


def participant():
    return DomainParticipant(0, qos=Qos(Policy.Userdata(USER_DATA)))


def guid(key):
    return key.bytes.hex()


def lowstate(tick):
    state = unitree_go_msg_dds__LowState_()
    state.head = [0xFE, 0xEF]
    state.tick = tick
    state.motor_state[0].q = 0.001 * tick
    state.crc = crc.Crc(state)
    return state


def hg_lowstate(tick):
    state = unitree_hg_msg_dds__LowState_()
    state.tick = tick
    state.mode_machine = 5
    for i in range(35):
        state.motor_state[i].q = 0.001 * tick + i
    state.crc = crc.Crc(state)
    return state


def endpoint(e):
    return {"guid": guid(e.key), "participant": guid(e.participant_key), "topic": e.topic_name, "type": e.type_name}


def discovery():
    dp = participant()
    writer = DataWriter(dp, Topic(dp, "rt/lowstate", LowState_))
    reader = DataReader(dp, Topic(dp, "rt/lowcmd", LowCmd_))
    say(
        "ready",
        participant=guid(dp.guid),
        writer=guid(writer.guid),
        reader=guid(reader.guid),
        cyclonedds=importlib.metadata.version("cyclonedds"),
        libddsc=os.path.basename(library.library_path),
    )
    participants = BuiltinDataReader(dp, BuiltinTopicDcpsParticipant)
    publications = BuiltinDataReader(dp, BuiltinTopicDcpsPublication)
    subscriptions = BuiltinDataReader(dp, BuiltinTopicDcpsSubscription)
    seen = {"participants": {}, "publications": {}, "subscriptions": {}}

    def look():
        for p in participants.take(N=64):
            user_data = p.qos[Policy.Userdata]
            seen["participants"][guid(p.key)] = user_data.data.decode("latin-1") if user_data else None
        for e in publications.take(N=64):
            seen["publications"][guid(e.key)] = endpoint(e)
        for e in subscriptions.take(N=64):
            seen["subscriptions"][guid(e.key)] = endpoint(e)
        ros = [k for k, u in seen["participants"].items() if u == "enclave=/;"]
        mine = lambda table: [e for e in table.values() if e["participant"] in ros]  # noqa: E731
        return bool(ros) and mine(seen["publications"]) and mine(seen["subscriptions"])

    until(look, "no participant with USER_DATA enclave=/; and a writer and a reader of it")
    say(
        "discovered",
        participants=seen["participants"],
        publications=list(seen["publications"].values()),
        subscriptions=list(seen["subscriptions"].values()),
    )
    wait_word("quit")
    del writer, reader


def stream(qos_name, count, hg=False):
    count = int(count)
    dp = participant()
    qos = Qos(reliability(qos_name), Policy.History.KeepLast(count + 10))
    state_type = HgLowState_ if hg else LowState_
    writes, reads = Watch(), Watch()
    writer = DataWriter(dp, Topic(dp, "rt/lowstate", state_type), qos=qos, listener=writes.listener)
    if hg:
        topic = Topic(dp, "rt/lowstate_back", HgLowState_)
    else:
        topic = Topic(dp, "rt/lowcmd", LowCmd_)
    reader = DataReader(dp, topic, qos=qos, listener=reads.listener)
    until(
        lambda: writes.get()[0] >= 1 and reads.get()[0] >= 1,
        "robowire's reader and writer never matched",
    )
    say("matched", writer=guid(writer.guid), reader=guid(reader.guid))
    if wait_word("go") == "quit":
        return
    received = []
    crc_bad = 0

    def take():
        nonlocal crc_bad
        for m in reader.take(N=count + 10):
            if crc.Crc(m) != m.crc:
                crc_bad += 1
            received.append(m)

    for tick in range(1, count + 1):
        writer.write(hg_lowstate(tick) if hg else lowstate(tick))
        take()
        time.sleep(0.001)
    end = time.time() + DEADLINE_S
    while len(received) < count and time.time() < end and not heard("quit"):
        take()
        time.sleep(0.002)
    tags = [m.tick if hg else m.reserve for m in received]
    say(
        "summary",
        written=count,
        received=len(received),
        crc_bad=crc_bad,
        tags=tags,
        last_q0=received[-1].motor_state[0].q if hg and received else (received[-1].motor_cmd[0].q if received else None),
    )
    # Let a reliable writer's last samples be acknowledged before the participant goes.
    if qos_name == "reliable":
        try:
            writer.wait_for_acks(2_000_000_000)
        except Exception:  # noqa: BLE001: best effort at leaving cleanly
            pass
    wait_word("quit")


def late_writer(count):
    count = int(count)
    dp = participant()
    # CycloneDDS keeps for late joiners what DURABILITY_SERVICE's history says (keep last 1 by
    # default), not HISTORY's.
    qos = Qos(
        Policy.Reliability.Reliable(max_blocking_time=100_000_000),
        Policy.Durability.TransientLocal,
        Policy.History.KeepLast(count),
        Policy.DurabilityService(
            cleanup_delay=0,
            history=Policy.History.KeepLast(count),
            max_samples=-1,
            max_instances=-1,
            max_samples_per_instance=-1,
        ),
    )
    writer = DataWriter(dp, Topic(dp, "rt/lowstate", LowState_), qos=qos)
    for tick in range(1, count + 1):
        writer.write(lowstate(tick))
    say("written", count=count, writer=guid(writer.guid))
    wait_word("quit", deadline=60)


def late_reader(count):
    count = int(count)
    dp = participant()
    qos = Qos(
        Policy.Reliability.Reliable(max_blocking_time=100_000_000),
        Policy.Durability.TransientLocal,
        Policy.History.KeepLast(count + 10),
    )
    reader = DataReader(dp, Topic(dp, "rt/lowstate", LowState_), qos=qos)
    received = []
    crc_bad = 0

    def enough():
        nonlocal crc_bad
        for m in reader.take(N=count + 10):
            crc_bad += crc.Crc(m) != m.crc
            received.append(m.tick)
        return len(received) >= count

    until(enough, f"fewer than {count} samples from a transient-local writer")
    time.sleep(0.2)
    enough()
    say("summary", received=len(received), ticks=received, crc_bad=crc_bad)


def incompatible():
    dp = participant()
    requested, offered = Watch(), Watch()
    reliable = Qos(Policy.Reliability.Reliable(max_blocking_time=100_000_000))
    reader = DataReader(dp, Topic(dp, "rt/lowcmd", LowCmd_), qos=reliable, listener=requested.listener)
    best_effort = Qos(Policy.Reliability.BestEffort)
    writer = DataWriter(dp, Topic(dp, "rt/lowstate", LowState_), qos=best_effort, listener=offered.listener)
    say("ready", participant=guid(dp.guid), reader=guid(reader.guid), writer=guid(writer.guid))
    until(
        lambda: requested.get()[1] and offered.get()[1],
        "no incompatible-QoS status on both of Cyclone's endpoints",
    )
    # Anything that would follow (a match after all) has time to show.
    time.sleep(0.5)
    (reader_matched, requested_statuses), (writer_matched, offered_statuses) = requested.get(), offered.get()
    say(
        "incompatible",
        requested=requested_statuses,
        offered=offered_statuses,
        reader_matched=reader_matched,
        writer_matched=writer_matched,
    )
    wait_word("quit")


def heartbeat():
    dp = participant()
    qos = Qos(Policy.Reliability.Reliable(max_blocking_time=100_000_000), Policy.History.KeepLast(1))
    writer = DataWriter(dp, Topic(dp, "rt/lowstate", LowState_), qos=qos)
    reader = DataReader(dp, Topic(dp, "rt/lowcmd", LowCmd_))
    say("ready", participant=guid(dp.guid), writer=guid(writer.guid), reader=guid(reader.guid))
    tick = 0
    received = 0
    said = False
    end = time.time() + 60
    while time.time() < end:
        tick += 1
        writer.write(lowstate(tick))
        for m in reader.take(N=16):
            received += crc.Crc(m) == m.crc
        if received and not said:
            say("receiving", lowcmds=received)
            said = True
        if heard("quit"):
            break
        time.sleep(0.01)
    say("summary", written=tick, lowcmds=received)


SCENARIOS = {
    "discovery": discovery,
    "stream": stream,
    "fragments": lambda count: stream("reliable", count, hg=True),
    "late_writer": late_writer,
    "late_reader": late_reader,
    "incompatible": incompatible,
    "heartbeat": heartbeat,
}

if __name__ == "__main__":
    SCENARIOS[sys.argv[1]](*sys.argv[2:])

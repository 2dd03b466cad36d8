#!/usr/bin/env python3
"""cell-agent and its default SQLite store (results/results.db), against a
surfinspectd on loopback:

1. A reader while the agent writes: `surfinspect trend` runs in a loop while
   an agent records 10 parts. Every call succeeds (or, before the first
   part, says there are none); the part count never falls; several reads
   see a partial history, so the reads did overlap the writes.
2. Killed mid-write: the agent runs under strace, which kills it with
   SIGKILL on entry to the KILL_AT-th pwrite64 to results.db-wal, that is
   inside SQLite's commit of a part (the frames of a transaction are
   written at commit, the last one marked as the commit frame). The trace
   shows which transaction was cut. Then the database holds only whole
   parts, the cut part's files are there but the part is not recorded, and
   the restarted agent records every part exactly once.

usage: agent_sqlite_test.py BIN_DIR
"""
import json
import os
import re
import shutil
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import agent_store_test as store  # noqa: E402  (make_cells, agent, free_port)

BIN = store.BIN
KILL_AT = 90  # about the middle of the second part's commit (48 pwrites a part)


def expect(cond, what):
    if not cond:
        sys.exit("FAIL: " + what)


def trend(db, cell, work):
    """(parts, error) from one `surfinspect trend` call."""
    out = os.path.join(work, "reader.json")
    p = subprocess.run([os.path.join(BIN, "surfinspect"), "trend", "--db", db, "--cell", cell,
                        "--out", os.path.join(work, "reader.html"), "--json", out],
                       capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr.strip()
    with open(out) as f:
        t = json.load(f)
    expect(len(set(t["part_ids"])) == t["parts"], "doubled parts in %s" % t["part_ids"])
    return t["parts"], None


def reader_while_writing(cell_dir, target, work):
    db = os.path.join(cell_dir, "results", "results.db")
    a = store.agent(cell_dir, target, "", "--simulate", "10", "--once", "--seed", "5")
    counts, errors = [], []
    while a.poll() is None:
        parts, err = trend(db, "cell-r", work)
        if err is None:
            expect(not counts or parts >= counts[-1], "the part count fell: %s then %d" % (counts, parts))
            counts.append(parts)
        elif "no parts match" in err or "no such results database" in err:
            expect(not counts, "after %s parts, trend says: %s" % (counts, err))
        else:
            errors.append(err)
    out, err = a.communicate()
    expect(a.returncode == 0, "agent failed:\n%s\n%s" % (out, err))
    expect(not errors, "trend failed while the agent wrote: %s" % errors[:3])
    partial = [c for c in counts if 0 < c < 10]
    expect(len(partial) >= 2, "only %d reads saw a partial history (%s): no overlap shown" %
           (len(partial), counts))
    parts, err = trend(db, "cell-r", work)
    expect(parts == 10, "after the run: %s %s" % (parts, err))
    print("reader during writes: %d trend calls, %d of them while 1-9 parts were recorded, "
          "counts %s, no error" % (len(counts), len(partial), counts), flush=True)


def frames(trace):
    """pwrite64 calls to the WAL in order: (index, is_commit_frame_header)."""
    out = []
    for line in open(trace):
        m = re.search(r'pwrite64\(\d+, "((?:\\x[0-9a-f]{2})*)"(?:\.\.\.)?, (\d+), \d+(?:\)| <unfinished)', line)
        if not m:
            continue
        body = bytes(int(h, 16) for h in re.findall(r"\\x([0-9a-f]{2})", m.group(1)))
        # A WAL frame header is 24 bytes; bytes 4..7 are the database size
        # after the commit, non-zero only in a transaction's last frame.
        out.append(int(m.group(2)) == 24 and int.from_bytes(body[4:8], "big") != 0)
    return out


def recorded(db):
    """{part_id: (characteristic rows, triangle rows)} of the parts table."""
    con = sqlite3.connect(db)
    try:
        rows = con.execute(
            "SELECT p.part_id, (SELECT count(*) FROM characteristics c WHERE c.cell = p.cell AND "
            "c.part_id = p.part_id), (SELECT count(*) FROM triangle_summaries t WHERE t.cell = "
            "p.cell AND t.part_id = p.part_id) FROM parts p").fetchall()
    finally:
        con.close()
    return {r[0]: (r[1], r[2]) for r in rows}


def whole(cell_dir, parts):
    for part, (chars, tris) in parts.items():
        with open(os.path.join(cell_dir, "results", part, "report.json")) as f:
            want = len(json.load(f)["characteristics"])
        expect(chars == want and tris == 1, "%s recorded with %d of %d characteristics and %d "
               "triangle summaries" % (part, chars, want, tris))


def killed_mid_commit(cell_dir, target, work):
    db = os.path.join(cell_dir, "results", "results.db")
    trace = os.path.join(work, "wal.trace")
    cmd = ["strace", "-f", "-qq", "-xx", "-o", trace, "-P", db + "-wal", "-e", "trace=pwrite64",
           "-e", "inject=pwrite64:signal=SIGKILL:when=%d" % KILL_AT] + \
        store.agent_command(cell_dir, target, "", "--simulate", "6", "--once", "--seed", "6")
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    expect(p.returncode == -signal.SIGKILL or p.returncode == 128 + signal.SIGKILL,
           "the agent was not killed (rc %d):\n%s" % (p.returncode, p.stderr[-2000:]))
    f = frames(trace)
    commits = [i for i, c in enumerate(f) if c]
    expect(len(f) == KILL_AT, "traced %d pwrites, the kill was at %d" % (len(f), KILL_AT))
    expect(len(commits) >= 2 and commits[-1] < KILL_AT - 2,
           "the kill did not land inside a part's commit: commit frames at %s" % commits)
    # The schema's migration is the first transaction; each later one is a part.
    done = recorded(db)
    whole(cell_dir, done)
    expect(len(done) == len(commits) - 1, "%d parts recorded, %d part commits completed" %
           (len(done), len(commits) - 1))
    files = sorted(d for d in os.listdir(os.path.join(cell_dir, "results"))
                   if os.path.exists(os.path.join(cell_dir, "results", d, "report.json")))
    cut = [d for d in files if d not in done]
    expect(cut, "every part with files is recorded: the kill cut no part's transaction")
    print("killed on pwrite %d, %d pwrites into a commit: %d whole parts recorded, %s cut "
          "(its files are there, the part is not)" %
          (KILL_AT, KILL_AT - 1 - commits[-1], len(done), cut), flush=True)
    r = store.agent(cell_dir, target, "", "--once")
    out, err = r.communicate(timeout=300)
    expect(r.returncode == 0, "restarted agent failed:\n%s\n%s" % (out, err))
    after = recorded(db)
    whole(cell_dir, after)
    con = sqlite3.connect(db)
    rows = con.execute("SELECT count(*) FROM parts").fetchone()[0]
    con.close()
    expect(rows == 6 and len(after) == 6 and set(files) <= set(after),
           "after the restart: %d rows, %s" % (rows, sorted(after)))
    print("restarted: all 6 parts recorded once, each whole", flush=True)


def main():
    if not shutil.which("strace"):
        sys.exit("FAIL: strace is not installed (./run deps installs it)")
    work = tempfile.mkdtemp(prefix="agent-sqlite-")
    server = None
    try:
        cells = store.make_cells(work, ["cell-r", "cell-k"])
        port = store.free_port()
        server = subprocess.Popen([os.path.join(BIN, "surfinspectd"), "--listen",
                                   "127.0.0.1:%d" % port, "--threads", "1"],
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        expect("listening on" in server.stdout.readline(), "surfinspectd did not start")
        target = "127.0.0.1:%d" % port
        t0 = time.time()
        reader_while_writing(cells["cell-r"], target, work)
        killed_mid_commit(cells["cell-k"], target, work)
        print("ok in %.1f s" % (time.time() - t0))
    finally:
        if server:
            server.send_signal(signal.SIGTERM)
            server.wait(timeout=30)
        if os.environ.get("KEEP") is None:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()

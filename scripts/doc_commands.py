#!/usr/bin/env python3
"""Runs the commands of the README's and docs/'s fenced ```sh blocks as written and reports which fail.

Called by `scripts/readme_figures.sh --commands [--slow] [--timeout S] [--out DIR] [FILE.md...]` from the
repository root. A command is one line of a ```sh (or ```bash) block, with lines ending in a backslash joined;
blank lines and lines that are only a comment are not commands. A command whose comment says `# slow:` is skipped
unless --slow is given; one whose comment says `# elsewhere:` (for another machine, such as an SSH tunnel) is
never run. Each runs in `bash -c` from the repository root, in a process group of its own that is
stopped when the command ends or its time is up, with its output kept in OUT/NNN.log.
"""
import argparse
import glob
import os
import re
import signal
import subprocess
import sys
import time

SLOW = re.compile(r"#\s*slow:")
ELSEWHERE = re.compile(r"#\s*elsewhere:")
FENCE_OPEN = re.compile(r"^\s*```(sh|bash)\s*$")
FENCE_CLOSE = re.compile(r"^\s*```\s*$")


def commands(path):
    """(line number, command) for every command of the file's ```sh blocks."""
    found, inside, pending, start = [], False, "", 0
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if not inside:
                inside = bool(FENCE_OPEN.match(line))
                continue
            if FENCE_CLOSE.match(line):
                inside = False
                continue
            if not pending:
                start = number
            if line.rstrip().endswith("\\"):
                pending += line.rstrip()[:-1] + " "
                continue
            command, pending = (pending + line).strip(), ""
            if command and not command.startswith("#"):
                found.append((start, command))
    return found


def run(command, log_path, timeout_s):
    """Exit status of the command (None when its time ran out) and its wall seconds."""
    began = time.monotonic()
    with open(log_path, "w", encoding="utf-8") as log:
        log.write(f"$ {command}\n")
        log.flush()
        child = subprocess.Popen(["bash", "-c", command], stdout=log, stderr=subprocess.STDOUT,
                                 stdin=subprocess.DEVNULL, start_new_session=True)
        try:
            status = child.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            status = None
        try:  # whatever the command left running in its group (a server, a device in the background)
            os.killpg(child.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        if status is None:
            child.wait()
    return status, time.monotonic() - began


def tail(path, lines=6):
    with open(path, encoding="utf-8", errors="replace") as f:
        return [l.rstrip("\n") for l in f.readlines()[-lines:]]


def main():
    parser = argparse.ArgumentParser(prog="readme_figures.sh --commands")
    parser.add_argument("files", nargs="*", help="Markdown files (default: README.md docs/*.md)")
    parser.add_argument("--slow", action="store_true", help="also run the commands marked # slow:")
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per command")
    parser.add_argument("--out", default="out/readme_commands", help="folder for the logs")
    args = parser.parse_args()
    files = args.files or ["README.md"] + sorted(glob.glob("docs/*.md"))
    os.makedirs(args.out, exist_ok=True)
    failed, ran, skipped, index = [], 0, 0, 0
    for path in files:
        for number, command in commands(path):
            where = f"{path}:{number}"
            if "readme_figures.sh --commands" in command:  # this check itself
                continue
            if ELSEWHERE.search(command):
                skipped += 1
                print(f"skip  {where}  {command}", flush=True)
                continue
            if SLOW.search(command) and not args.slow:
                skipped += 1
                print(f"skip  {where}  {command}", flush=True)
                continue
            index += 1
            log_path = os.path.join(args.out, f"{index:03d}.log")
            status, wall_s = run(command, log_path, args.timeout)
            ran += 1
            if status == 0:
                print(f"ok    {where}  ({wall_s:.1f} s)  {command}", flush=True)
                continue
            why = f"stopped after {args.timeout:g} s" if status is None else f"exit {status}"
            failed.append((where, command, why, log_path))
            print(f"FAIL  {where}  ({why}, {wall_s:.1f} s)  {command}", flush=True)
            for line in tail(log_path):
                print(f"        {line}", flush=True)
    print(f"\ndoc commands: {ran} run, {len(failed)} failed, {skipped} skipped as slow"
          f"{'' if args.slow else ' (--slow runs them)'}; logs in {args.out}")
    for where, command, why, log_path in failed:
        print(f"  failed: {where} ({why}; {log_path}): {command}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

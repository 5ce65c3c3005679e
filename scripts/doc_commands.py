#!/usr/bin/env python3
"""Runs the commands of the README's and docs/'s fenced ```sh blocks as written and reports which fail.

Every fence must say what it holds: ```sh (or ```bash) for commands, ```text (or another language) for output,
transcripts and diagrams. An untagged fence is reported as a failure (its lines would be taken for neither), so a
command cannot hide in one.

Called by `scripts/readme_figures.sh --commands [--slow] [--timeout S] [--out DIR] [FILE.md...]` from the
repository root. A command is one line of a ```sh (or ```bash) block, with lines ending in a backslash joined;
blank lines and lines that are only a comment are not commands. A line that only sets variables (`A=/usr/share/...`)
is carried into the block's later commands, as a shell it is pasted into keeps it. A command whose comment says `# slow:` is skipped
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
FENCE_ANY = re.compile(r"^\s*```(\S*)\s*$")
FENCE_CLOSE = re.compile(r"^\s*```\s*$")
ASSIGNMENTS = re.compile(r"""^(\s*[A-Za-z_][A-Za-z0-9_]*=("[^"]*"|'[^']*'|[^\s"']+))+\s*$""")


def untagged_fences(path):
    """Line numbers of the file's fences that open without a language."""
    found, inside = [], False
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            m = FENCE_ANY.match(line.rstrip("\n"))
            if not m:
                continue
            if not inside and m.group(1) == "":
                found.append(number)
            inside = not inside
    return found


def commands(path):
    """(line number, command) for every command of the file's ```sh blocks."""
    found, inside, shell, pending, start, env = [], False, False, "", 0, ""
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.rstrip("\n")
            m = FENCE_ANY.match(line)
            if not inside:
                if m:
                    inside, shell, env = True, m.group(1) in ("sh", "bash"), ""
                continue
            if FENCE_CLOSE.match(line):
                inside = False
                continue
            if not shell:
                continue
            if not pending:
                start = number
            if line.rstrip().endswith("\\"):
                pending += line.rstrip()[:-1] + " "
                continue
            command, pending = (pending + line).strip(), ""
            if ASSIGNMENTS.match(command):
                env += command.strip() + "; "
                continue
            if command and not command.startswith("#"):
                found.append((start, env + command))
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


def tree_state():
    """What git sees outside the ignored folders (out/, build/): each changed or new path with its file's size and
    time, so a command that writes into the repository is caught (None outside a git checkout)."""
    try:
        lines = subprocess.run(["git", "status", "--porcelain", "--untracked-files=all"], capture_output=True,
                               text=True, check=True).stdout.splitlines()
    except (OSError, subprocess.CalledProcessError):
        return None
    state = {}
    for line in lines:
        path = line[3:]
        try:
            st = os.stat(path)
            state[path] = (st.st_size, st.st_mtime_ns)
        except OSError:
            state[path] = None
    return state


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
    before = tree_state()
    for path in files:
        for number in untagged_fences(path):
            failed.append((f"{path}:{number}", "```", "an untagged fence: tag it sh (commands) or text (output)", "-"))
            print(f"FAIL  {path}:{number}  an untagged fence: tag it sh (commands) or text (output)", flush=True)
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
    # a command writes its outputs under out/ (ignored): one that wrote into the repository is a failure
    after = tree_state()
    if before is not None and after is not None:
        touched = sorted(p for p in after if after[p] != before.get(p, "absent"))
        if touched:
            failed.append(("the repository", ", ".join(touched[:5]) + (" ..." if len(touched) > 5 else ""),
                           f"{len(touched)} file(s) written outside out/", "-"))
            print(f"FAIL  the commands wrote {len(touched)} file(s) outside out/: {', '.join(touched[:5])}", flush=True)
    print(f"\ndoc commands: {ran} run, {len(failed)} failed, {skipped} skipped as slow"
          f"{'' if args.slow else ' (--slow runs them)'}; logs in {args.out}")
    for where, command, why, log_path in failed:
        print(f"  failed: {where} ({why}; {log_path}): {command}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

"""The command-line frame shared by the benchmark scripts (scaling.py, scene_times.py): errors as
`NAME: error: ...` with exit code 2, and `NAME COMMAND ARGS...` dispatched to a function per command."""
import os
import sys


def die(message):
    sys.stderr.write("%s: error: %s\n" % (os.path.basename(sys.argv[0]), message))
    sys.exit(2)


def dispatch(doc, commands):
    """Runs commands[argv[1]](argv[2:]); prints `doc` for -h/--help (exit 0) or no command (exit 2)."""
    if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help"):
        print(doc)
        return 0 if len(sys.argv) >= 2 else 2
    command = commands.get(sys.argv[1])
    if command is None:
        die("unknown command " + sys.argv[1])
    command(sys.argv[2:])
    return 0

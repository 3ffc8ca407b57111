import sys

try:
    from mocap.cli import run
except KeyboardInterrupt:                 # Ctrl-C while the shell itself loads
    sys.stderr.write("mocap: interrupted\n")
    sys.exit(130)

run()

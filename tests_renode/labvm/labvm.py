#!/usr/bin/python3
"""The lab VM's command line; see cli.py or `labvm.py --help`."""

import os
import sys

# Run as a script, this folder is sys.path[0] and 'labvm' would be this file;
# the package is found from the folder above.
sys.path[0] = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

from labvm.cli import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())

"""python3 -m labvm (from tests_renode/): the lab VM's command line."""

import sys

from .cli import main

sys.exit(main())

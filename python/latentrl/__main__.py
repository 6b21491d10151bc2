"""`python -m latentrl` is the `latentrl` command."""

import sys

from latentrl.cli import main

sys.exit(main())

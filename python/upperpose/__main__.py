"""`python -m upperpose` runs the command line."""

import sys

from upperpose.cli import main

sys.exit(main())

"""`python -m jaxcable`: the same as the `jaxcable` command."""

import sys

from ._cli import main

sys.exit(main())

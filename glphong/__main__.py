"""``python -m glphong``: see `glphong.cli`."""
import sys

from .cli import main

sys.exit(main())

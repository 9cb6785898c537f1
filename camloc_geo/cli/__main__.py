import sys

from camloc_geo.cli import main

sys.exit(main())

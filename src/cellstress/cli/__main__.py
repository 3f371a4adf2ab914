import sys

from cellstress.cli import main

sys.exit(main())

"""Allows ``python -m mtpg``."""

from mtpg.cli.main import main

raise SystemExit(main())

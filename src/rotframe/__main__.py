from rotframe.cli import main

raise SystemExit(main())

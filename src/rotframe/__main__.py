from rotframe.app.console import main

raise SystemExit(main())

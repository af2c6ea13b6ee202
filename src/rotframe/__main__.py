from rotframe._console import main

raise SystemExit(main())

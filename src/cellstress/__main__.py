from cellstress.cli import main

main()

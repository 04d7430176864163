# the panel's browser tests (tests/gtecat/inspect/test_panel_browser.py)
DEBS="chromium chromium-driver"

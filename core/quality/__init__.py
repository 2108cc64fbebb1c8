"""Quality: accuracy statistics, published standards, HTML reports and their SVG plots."""

# Helpers the study reports share; sourced, not run.

# The values of a run's observable, one per line (frame 0 first): observable FILE NAME.
observable() {
  h5dump -m %.10g -d "/observables/$2/value" -y -w 0 "$1" |
    awk '/DATA \{/ { on = 1; next } on && /\}/ { exit } on { gsub(/,/, " "); for (k = 1; k <= NF; k++) print $k }'
}

# A length "5mm", "0.5cm" or "0.005" (metres) in metres.
in_metres() {
  awk -v d="$1" 'BEGIN { v = d + 0; if (d ~ /mm$/) v /= 1000; else if (d ~ /cm$/) v /= 100; print v }'
}

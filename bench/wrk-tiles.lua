-- wrk: every request fetches the next tile content of the tileset (paths from tiles.txt, one per
-- line), so the server reads many files, not one cached path.
local paths = {}
for line in io.lines(os.getenv("TILES_LIST") or "tiles.txt") do paths[#paths + 1] = line end
local i = 0
request = function()
  i = i % #paths + 1
  return wrk.format("GET", paths[i])
end
done = function(summary, latency, requests)
  io.write(string.format("errors: connect %d, read %d, write %d, status %d, timeout %d\n",
                         summary.errors.connect, summary.errors.read, summary.errors.write,
                         summary.errors.status, summary.errors.timeout))
end

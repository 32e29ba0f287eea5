-- The file cases the long fuzz runs found failing (scripts/fuzz), replayed
-- one by one: each must pass now (each failed on the code of its run).
--   FUZZ_SEIXO=seixo FUZZ_H5MUTATE=h5mutate seixo tests/fuzz/found.lua
local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
local seixo_exe = assert(os.getenv("FUZZ_SEIXO"), "FUZZ_SEIXO: the seixo program")
local found = {
  {2026120217, 1218, "a bond's bending moment of 1e300: a NaN crack"},
  {2026120217, 1461, "a zero-length relative position: a NaN normal"},
  {2026120218, 123, "a ball's spin of 1e300: a NaN crack"},
  {2026120219, 180, "a bond's ks of 1e300: a NaN crack"},
  {2026120219, 192, "a bond's radius of 1e300: a NaN crack"},
}
local failed = 0
for _, f in ipairs(found) do
  local cmd = string.format("FUZZ_SEED=%d FUZZ_FIRST=%d FUZZ_COUNT=1 %q %q 2>&1", f[1], f[2], seixo_exe,
                            here .. "files.lua")
  local p = assert(io.popen(cmd))
  local out = p:read("a")
  p:close()
  local ok = out:find(", 0 failed", 1, true) ~= nil
  print(string.format("%s seed %d case %d (%s)", ok and "ok" or "FAIL", f[1], f[2], f[3]))
  if not ok then failed = failed + 1; io.write(out) end
end
print(string.format("%d passed, %d failed", #found - failed, failed))
os.exit(failed == 0 and 0 or 1)

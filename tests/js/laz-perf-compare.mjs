// A second, independent LAZ decoder for the tests: npm's laz-perf (LASzip compiled to
// WebAssembly) decodes LAZ, and every record must equal the one lodforge wrote to the LAS.
//   node laz-perf-compare.mjs FILE.laz LODFORGE.las
// Exit 0 when all records match, 1 with the first difference otherwise.
import { readFileSync } from 'node:fs';
import { createLazPerf } from 'laz-perf';

const [lazPath, lasPath] = process.argv.slice(2);
if (!lazPath || !lasPath) {
  console.error('usage: node laz-perf-compare.mjs FILE.laz LODFORGE.las');
  process.exit(2);
}
const laz = readFileSync(lazPath);
const las = readFileSync(lasPath);
const pointOffset = las.readUInt32LE(96);
const recordLength = las.readUInt16LE(105);

const lazPerf = await createLazPerf();
const filePtr = lazPerf._malloc(laz.length);
lazPerf.HEAPU8.set(laz, filePtr);
const reader = new lazPerf.LASZip();
reader.open(filePtr, laz.length);
const count = reader.getCount();
const length = reader.getPointLength();
const lasCount = (las.length - pointOffset) >= count * recordLength ? count : -1;
if (length !== recordLength || lasCount !== count) {
  console.error(`${lazPath}: laz-perf reads ${count} records of ${length} bytes; ` +
                `${lasPath} has records of ${recordLength} bytes from byte ${pointOffset}`);
  process.exit(1);
}
const pointPtr = lazPerf._malloc(length);
for (let i = 0; i < count; ++i) {
  reader.getPoint(pointPtr);
  const theirs = lazPerf.HEAPU8.subarray(pointPtr, pointPtr + length);
  const ours = las.subarray(pointOffset + i * length, pointOffset + (i + 1) * length);
  if (Buffer.compare(Buffer.from(theirs), ours) !== 0) {
    console.error(`${lazPath}: record ${i} differs\n  laz-perf ${Buffer.from(theirs).toString('hex')}\n` +
                  `  lodforge ${ours.toString('hex')}`);
    process.exit(1);
  }
}
reader.delete();
console.log(`${lazPath}: ${count} records of ${length} bytes identical to laz-perf`);

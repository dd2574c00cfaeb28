-- how often each value fills each role of each robot predicate ($corpus: a corpus name or 'all')
select predicate, role, value, count(*) as n
from robot_fillers
where $corpus = 'all' or corpus = $corpus
group by all
order by all
